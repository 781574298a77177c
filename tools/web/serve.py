#!/usr/bin/env python3
"""./kit web --serve: a site served on 127.0.0.1 as a static host serves it, compressed.

    serve.py SITE_DIR PORT

python's http.server, with two things a static host does and it does not: a file goes out
gzip-compressed (Content-Encoding: gzip) when the browser accepts gzip and compression saves
a tenth of it (kit-web.wasm and kit-page.js shrink to a third; the grader's references do
not shrink and go as they are), and .wasm is served as application/wasm, which
WebAssembly's streaming compile needs. Static hosts such as GitHub Pages compress JavaScript,
CSS, HTML and JSON by themselves; whether they compress .wasm, .data and .zip depends on the
host (docs/web.md). The compressed bytes are kept in memory per file and modification time.
"""
import functools
import gzip
import http.server
import io
import os
import sys
import threading

SAVING = 0.9  # compressed only where it is at most this share of the file


class SiteHandler(http.server.SimpleHTTPRequestHandler):
    """SimpleHTTPRequestHandler, with gzip where the browser accepts it."""

    extensions_map = {**http.server.SimpleHTTPRequestHandler.extensions_map, ".wasm": "application/wasm",
                      ".data": "application/octet-stream", ".zip": "application/zip", ".json": "application/json"}
    _compressed = {}  # (path, mtime, size) -> gzip bytes, or None where gzip saves too little
    _lock = threading.Lock()

    def _gzip(self, path, stat):
        key = (path, stat.st_mtime_ns, stat.st_size)
        with self._lock:
            if key in self._compressed:
                return self._compressed[key]
        with open(path, "rb") as f:
            data = f.read()
        packed = gzip.compress(data, compresslevel=6, mtime=0)
        body = packed if len(packed) <= SAVING * len(data) else None
        with self._lock:
            self._compressed[key] = body
        return body

    def send_head(self):
        path = self.translate_path(self.path)
        accepts = "gzip" in self.headers.get("Accept-Encoding", "")
        if not accepts or not os.path.isfile(path):
            return super().send_head()
        stat = os.stat(path)
        body = self._gzip(path, stat)
        if body is None:
            return super().send_head()
        self.send_response(200)
        self.send_header("Content-Type", self.guess_type(path))
        self.send_header("Content-Encoding", "gzip")
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Vary", "Accept-Encoding")
        self.send_header("Last-Modified", self.date_time_string(stat.st_mtime))
        self.end_headers()
        return io.BytesIO(body)


def server(site, port=0, handler=SiteHandler):
    """A ThreadingHTTPServer on 127.0.0.1 (port 0: a free one) serving `site`; not started."""
    return http.server.ThreadingHTTPServer(("127.0.0.1", port), functools.partial(handler, directory=str(site)))


def main(argv):
    if len(argv) != 3 or not argv[2].isdigit():
        raise SystemExit(__doc__)
    httpd = server(argv[1], int(argv[2]))
    try:
        httpd.serve_forever()
    except KeyboardInterrupt:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
