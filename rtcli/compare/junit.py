"""The JUnit XML file of `rtcli compare ... --junit FILE`, which CI systems show as test results.

One test suite, one test case per pair (named by its relative path): an ok pair
passes, a failing or extra one is a <failure> whose message is its summary line, a
missing or unreadable one (it could not be compared: no render, or a broken file) an
<error> (folders.Pair.result). The file follows the Apache Ant JUnit schema,
the strictest of the common ones (every attribute it requires, <properties>,
<system-out> and <system-err>), so the looser readers of GitLab, Jenkins or GitHub
actions read it too. Text is kept on one line and free of the control characters
XML cannot hold (errors.one_line).
"""

from __future__ import annotations

import datetime
import socket
import xml.etree.ElementTree as ET

from rtcli.compare.folders import Pair, total_line
from rtcli.errors import one_line
from rtcli.rendering.writer import write_atomic


def junit_xml(pairs: list[Pair], properties: dict[str, str], seconds: float) -> bytes:
    """The document, as UTF-8 bytes."""
    results = [pair.result for pair in pairs]
    suite = ET.Element("testsuite", {
        "name": "rtcli compare", "package": "rtcli", "id": "0",
        "timestamp": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%S"),
        "hostname": one_line(socket.gethostname()) or "localhost",
        "tests": str(len(pairs)), "failures": str(results.count("failure")),
        "errors": str(results.count("error")), "skipped": "0", "time": f"{seconds:.3f}"})
    listed = ET.SubElement(suite, "properties")
    for name, value in properties.items():
        ET.SubElement(listed, "property", {"name": name, "value": one_line(value)})
    for pair in pairs:
        case = ET.SubElement(suite, "testcase", {"name": one_line(pair.path), "classname": "rtcli.compare",
                                                 "time": f"{pair.seconds:.3f}"})
        if not pair.ok:
            result = ET.SubElement(case, pair.result, {"message": one_line(pair.summary), "type": pair.status})
            result.text = one_line(pair.summary)
    ET.SubElement(suite, "system-out").text = total_line(pairs)
    ET.SubElement(suite, "system-err").text = ""
    root = ET.Element("testsuites")
    root.append(suite)
    ET.indent(root)
    return ET.tostring(root, encoding="utf-8", xml_declaration=True) + b"\n"


def write_junit(path: str, data: bytes) -> None:
    """Write the file atomically (a temporary file beside it, then a rename)."""
    write_atomic(path, lambda f: f.write(data))
