"""Comparing renders with golden images: two images through the golden gate (images.py), the
same for the Python API (difference.py), two folders paired by relative path (folders.py) and
run as a suite (suite.py) with an HTML report (report.py, report_html.py) and JUnit XML (junit.py).
"""
