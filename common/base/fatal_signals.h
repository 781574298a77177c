#pragma once
// A program's own report of a fatal signal: the handler runs on an alternate stack (so a
// stack overflow still reports) and once (SA_RESETHAND): raising the signal again from it
// ends the process with that signal, as it would have ended without the handler.

namespace kit {

// Installs `handler` for SIGSEGV, SIGBUS, SIGILL, SIGFPE and SIGABRT.
void on_fatal_signals(void (*handler)(int));

// Text to stderr with write(2) alone: what a signal handler may call.
void write_stderr(const char* text);

}  // namespace kit
