"""Looking inside a scene and a render: a pixel's ray tree (explain.py, raytree.py,
explain_text.py), the debug views (views.py), and `rtcli validate`'s listing and warnings
(checks.py), which renders print too (lint.py).
"""
