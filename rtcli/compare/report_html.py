"""The page of a comparison report (report.py): one table row per pair, in the order given.

Plain HTML with its style inline: it loads only the pictures beside it. Every text
from outside (paths, summaries) is kept on one line, a byte of a file name that is not
UTF-8 shown as \\xNN (errors.one_line), and escaped. Rows carry the class `pair`, their status
and, unless ok, their result (`error`: not compared, such as a golden without a render,
shown with the golden; `failure`), so a reader (or a test in a browser) can count them; a small script marks a
picture that did not load with the class `broken` and counts those that did in the
body's `data-images-loaded`.
"""

from __future__ import annotations

from html import escape

from rtcli.compare.folders import Pair, total_line
from rtcli.errors import one_line

STYLE = """
body { font: 14px/1.4 system-ui, sans-serif; margin: 1.5em; color: #222; }
table { border-collapse: collapse; }
th, td { border-bottom: 1px solid #ccc; padding: 6px; vertical-align: top; text-align: left; }
td img { width: 240px; height: auto; image-rendering: pixelated; border: 1px solid #999; }
img.broken { outline: 3px solid #d00; min-width: 40px; min-height: 30px; }
.path { font-weight: bold; word-break: break-all; max-width: 18em; }
.summary { font-family: monospace; font-size: 12px; max-width: 24em; }
.status { display: inline-block; padding: 0 6px; border-radius: 3px; color: #fff; background: #c00; }
.ok .status { background: #080; }
.error .status { background: #d06000; }
.result { margin-left: 4px; font-size: 12px; color: #555; }
.total { font-weight: bold; }
.note { font-size: 12px; max-width: 24em; color: #6a4a00; background: #fff4d6; padding: 2px 4px; margin-top: 4px; }
"""

LOADED = """
window.addEventListener("load", function () {
  var loaded = 0;
  for (var k = 0; k < document.images.length; k++) {
    var image = document.images[k];
    if (image.complete && image.naturalWidth > 0) { loaded++; } else { image.classList.add("broken"); }
  }
  document.body.setAttribute("data-images-loaded", String(loaded));
});
"""


def page(rows: list[Pair], pictures: dict, titles: tuple[str, str], gate_text: str, flip: bool) -> str:
    """The whole page: a header with the totals and the gate, then the table."""
    columns = ["actual", "expected", "difference"] + (["flip"] if flip else [])
    head = "".join(f"<th>{escape(c if c != 'flip' else 'FLIP')}</th>" for c in columns)
    body = "\n".join(_row(k, pair, pictures.get(pair.path, {}), columns) for k, pair in enumerate(rows, 1))
    actual, expected = (_text(t) for t in titles)
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<title>rtcli compare: {actual} against {expected}</title>
<style>{STYLE}</style></head>
<body data-rows="{len(rows)}">
<h1>rtcli compare</h1>
<p class="total">{escape(total_line(rows))}</p>
<p>actual: <code>{actual}</code>, expected: <code>{expected}</code>; {escape(gate_text)}.
Rows are worst first: errors (a pair that could not be compared: an expected image without an
actual one, such as a scene that failed to render, or an unreadable file), then failures.</p>
<table>
<thead><tr><th>image</th>{head}</tr></thead>
<tbody>
{body}
</tbody></table>
<script>{LOADED}</script>
</body></html>
"""


def _row(k: int, pair: Pair, names: dict, columns: list[str]) -> str:
    cells = "".join(_cell(names.get(c), c, pair.path) for c in columns)
    flip = f"<div>mean FLIP {pair.flip_mean:.4f}</div>" if pair.flip_mean is not None else ""
    flip += "".join(f'<div class="note">{escape(note)}</div>' for note in pair.notes)
    kind, result = ("", "") if pair.ok else (f" {pair.result}", f'<span class="result">{pair.result}</span>')
    return (f'<tr class="pair {pair.status}{kind}" id="pair-{k}"><td><div class="path">{_text(pair.path)}</div>'
            f'<span class="status">{escape(pair.status)}</span>{result}'
            f'<div class="summary">{_text(pair.summary)}</div>{flip}</td>{cells}</tr>')


def _cell(name: str | None, column: str, path: str) -> str:
    if name is None:
        return "<td>-</td>"
    return f'<td><a href="{name}"><img src="{name}" alt="{escape(column)} of {_text(path)}"></a></td>'


def _text(text: str) -> str:
    """Text from outside (a path, a summary) for the page: on one line, every byte shown, escaped."""
    return escape(one_line(text))
