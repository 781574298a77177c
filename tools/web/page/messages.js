// The message under the editor (#messages): what the page has to tell the student now, one
// at a time, with buttons where there is something to do about it. The last ones are kept in
// kitPage.messages for the page's test.
import {$} from "./state.js";

// actions: [{label, run}], buttons under the message.
export function say(page, text, kind = "", detail = "", actions = []) {
  const box = $("messages");
  box.className = kind;
  box.replaceChildren();
  const p = document.createElement("p");
  p.textContent = text;
  box.append(p);
  if (detail) {
    const pre = document.createElement("pre");
    pre.textContent = detail;
    box.append(pre);
  }
  if (actions.length) {
    const row = document.createElement("p");
    for (const action of actions) {
      const button = document.createElement("button");
      button.type = "button";
      button.textContent = action.label;
      button.addEventListener("click", action.run);
      row.append(button, " ");
    }
    box.append(row);
  }
  const messages = page.kitPage.messages;
  if (text) messages.push(text + (detail ? "\n" + detail : ""));
  if (messages.length > 50) messages.shift();
}

// A message with a failure when there is one.
export const showsError = () => $("messages").classList.contains("error");
