// What the progress report needs beyond the page: markdown-it for the notes, mustache.js and
// the layout ./kit progress-report fills too (tools/progress/report.mustache). Bundled apart,
// as kit-report.js, and loaded at the first report (report.js): a first visit loads kit-page.js
// before its first frame, and these are a fifth of it (docs/performance.md, A first visit).
import MarkdownIt from "markdown-it";
import Mustache from "mustache";
import TEMPLATE from "../../progress/report.mustache";

window.kitReportLibs = {MarkdownIt, Mustache, TEMPLATE};
