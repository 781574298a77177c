"""The parts of ./kit progress-report (tools/progress_report.py): results.py collects each
lab's results, layout.py fills the report's HTML layout (report.mustache, which the page's
"Progress report" fills too) and prints it to PDF."""
