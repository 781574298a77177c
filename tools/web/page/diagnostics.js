// A compile error's lines that name a file and a line, as kit-web's errors name the student's
// files: "/kit/labs/02-lighting/brdf.glsl:12: error: ...", "labs/02-lighting/brdf.glsl:12:5:
// error ...". Each becomes {path, line, column, message}, path as the page names files in
// kit-web's file system (/kit/labs/NN-name/FILE); column 0 when the line has none.
const LOCATION = /((?:labs|solutions|shaders)\/[^\s:'"()]+):(\d+)(?::(\d+))?:?\s*(.*)$/;

export function parseDiagnostics(text) {
  const out = [];
  for (const line of String(text || "").split("\n")) {
    const m = LOCATION.exec(line);
    if (!m) continue;
    out.push({path: "/kit/" + m[1], line: Number(m[2]), column: m[3] ? Number(m[3]) : 0,
              message: m[4].trim() || line.trim()});
  }
  return out;
}

// The diagnostics grouped by path.
export function byPath(diagnostics) {
  const out = new Map();
  for (const d of diagnostics) {
    if (!out.has(d.path)) out.set(d.path, []);
    out.get(d.path).push(d);
  }
  return out;
}
