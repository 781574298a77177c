"""The parts of ./kit progress-report (tools/progress_report.py): results.py collects each
lab's results, pdf.py draws pages, pages.py lays out the title and lab pages, notes.py the
student's Markdown notes."""
