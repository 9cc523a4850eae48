"""Two folders compared as a suite of golden tests, end to end:
`rtcli compare ACTUAL_DIR EXPECTED_DIR [--report DIR] [--junit FILE]`.

Outputs are checked before anything is compared (the report folder as report.py
says; the JUnit file as any output: never an input, a folder or a device). Then
every pair is compared (folders.py), one line printed per pair and one for the
totals; the report and the JUnit file are written last, each all or nothing.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable

from rtcli.compare.folders import compare_folders, images_under, total_line
from rtcli.compare.junit import junit_xml, write_junit
from rtcli.compare.report import Report, check_report_dir
from rtcli.errors import RtcliError, shown
from rtcli.rendering.outputs import check_file_output


def compare_dirs(actual: str, expected: str, image_options: dict, id_options: dict, report: str | None,
                 junit: str | None, echo: Callable[[str], None]) -> bool:
    """Compare the folders, print the lines, write the outputs; whether every pair passed."""
    _check_outputs(actual, expected, report, junit)
    start = time.perf_counter()
    built = Report(report, image_options["tolerance"], (actual, expected),
                   image_options.get("float_tolerance", 0.01)) if report else None
    try:
        pairs = compare_folders(actual, expected, image_options, id_options, built.keep if built else None)
        for pair in pairs:
            echo(f"{shown(pair.path)}: {pair.summary}")
            for note in pair.notes:
                echo(f"  {note}")
        echo(total_line(pairs))
        if built:
            built.finish(pairs, gate_text(image_options, id_options))
            built.place()
    finally:
        if built:
            built.discard()
    if junit:
        properties = {"actual": actual, "expected": expected, **{k: str(v) for k, v in image_options.items()},
                      **{k: str(v) for k, v in id_options.items()}}
        write_junit(junit, junit_xml(pairs, properties, time.perf_counter() - start))
    return all(pair.ok for pair in pairs)


def are_folders(actual: str, expected: str) -> bool:
    """Whether compare is given two folders (else two images). RtcliError naming the argument
    that does not exist, or both for a folder and a file."""
    for path, other in ((actual, expected), (expected, actual)):
        if not os.path.lexists(path):
            what = (f"folder (to compare with the folder {shown(other)})" if os.path.isdir(other)
                    else "file" if os.path.lexists(other) else "file or folder")
            raise RtcliError(f"{shown(path)}: no such {what}")
    folders = os.path.isdir(actual), os.path.isdir(expected)
    if folders[0] != folders[1]:
        folder, other = (actual, expected) if folders[0] else (expected, actual)
        raise RtcliError(f"{shown(folder)} is a folder but {shown(other)} is not: compare two folders or two images")
    return folders[0]


def _check_outputs(actual: str, expected: str, report: str | None, junit: str | None) -> None:
    inputs = list(images_under(actual).values()) + list(images_under(expected).values())
    if report:
        check_report_dir(report, [actual, expected])
    if junit:
        check_file_output(junit, inputs)
        if report and os.path.commonpath([os.path.realpath(junit), os.path.realpath(report)]) == \
                os.path.realpath(report):
            raise RtcliError(f"{shown(junit)}: inside the report folder, which is replaced as a whole")


def gate_text(image_options: dict, id_options: dict) -> str:
    """The gate in words, for the report's header."""
    o, i = image_options, id_options
    floats = f" ({o.get('float_tolerance', 0.01):g} x max(1, expected) in linear floats)"
    return (f"a pixel is bad beyond {o['tolerance']}/255{floats} in a channel; a pair fails with more than "
            f"max({o['max_bad_pixels']}, {o['max_bad_fraction']:g} of the pixels) bad pixels or a cluster "
            f"of more than {o['max_cluster']}; id maps allow max({i['max_boundary_mismatch']}, "
            f"{i['max_boundary_fraction']:g} of the boundary) mismatches on id boundaries, none elsewhere")
