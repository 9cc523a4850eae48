"""Named Phong material presets: the McReynolds/Blythe table of common materials.

Source: T. McReynolds and D. Blythe, "Advanced Graphics Programming Techniques
Using OpenGL", SIGGRAPH course notes (1998-2000), section "Choosing Material
Properties", table "Parameters for Common Materials"; reproduced in F.S. Hill,
"Computer Graphics Using OpenGL", 2nd ed., Figure 8.17.  The coloured plastics
and rubbers are the rest of the same OpenGL family of numbers, from Mark J.
Kilgard's teapots.c demo (SGI, 1994) as tabulated on F. Devernay's
"OpenGL/VRML Materials" page.

Each preset holds the ambient, diffuse and specular RGB reflectances and the
Phong specular EXPONENT n (what GL_SHININESS takes).  Devernay's page lists
shininess as a fraction f of 128; those entries are stored here as f*128
(e.g. copper 0.1 -> 12.8, plastics 0.25 -> 32, rubbers 0.078125 -> 10).  The
alpha components of the original table (1.0, or 0.55 / 0.95 / 0.82 / 0.922 /
0.8 for the gems) are left out: only RGB is kept.

Cross-checking notes (which sources agree, and what was chosen):

* Metals, gems, black plastic and black rubber: the SIGGRAPH notes (1998 and
  1999/2000 editions) and Devernay's page agree on every RGB number, and the
  exponents agree with Devernay's fractions times 128 - except brass, where
  0.21794872 * 128 = 27.897436...; the notes (and Hill) print 27.8974, which is
  what is stored.  Several code copies embedding the table agree too.
* Polished bronze/copper/gold/silver and pewter are only in the SIGGRAPH/Hill
  table (not on Devernay's page); they were checked against the 1998 and 1999
  notes and against several programs that embed the table.
* Copying slips seen elsewhere and NOT followed: brass ambient red 0.32941 and
  green 0.22352 (truncated), gold ambient green 0.21995 (for 0.1995), and a
  Hill-derived web page printing pewter ambient red as 0.10588 (for 0.105882).
* Coloured plastics and rubbers: Devernay's page and programs embedding it
  agree; their exponents are 32 (plastics) and 10 (rubbers), matching black
  plastic and black rubber in the SIGGRAPH table.
"""

from __future__ import annotations

from dataclasses import dataclass

RGB = tuple[float, float, float]


@dataclass(frozen=True)
class Preset:
    """One named material: Phong reflectances and specular exponent."""

    name: str
    ambient: RGB
    diffuse: RGB
    specular: RGB
    shininess: float  # the Phong exponent n, not a 0..1 fraction


def _grey(v: float) -> RGB:
    return (v, v, v)


_TABLE: list[Preset] = [
    # --- Metals (SIGGRAPH table; polished variants and pewter only there) ---
    Preset("brass",
           (0.329412, 0.223529, 0.027451),
           (0.780392, 0.568627, 0.113725),
           (0.992157, 0.941176, 0.807843), 27.8974),
    Preset("bronze",
           (0.2125, 0.1275, 0.054),
           (0.714, 0.4284, 0.18144),
           (0.393548, 0.271906, 0.166721), 25.6),
    Preset("polished_bronze",
           (0.25, 0.148, 0.06475),
           (0.4, 0.2368, 0.1036),
           (0.774597, 0.458561, 0.200621), 76.8),
    Preset("chrome",
           _grey(0.25),
           _grey(0.4),
           _grey(0.774597), 76.8),
    Preset("copper",
           (0.19125, 0.0735, 0.0225),
           (0.7038, 0.27048, 0.0828),
           (0.256777, 0.137622, 0.086014), 12.8),
    Preset("polished_copper",
           (0.2295, 0.08825, 0.0275),
           (0.5508, 0.2118, 0.066),
           (0.580594, 0.223257, 0.0695701), 51.2),
    Preset("gold",
           (0.24725, 0.1995, 0.0745),
           (0.75164, 0.60648, 0.22648),
           (0.628281, 0.555802, 0.366065), 51.2),
    Preset("polished_gold",
           (0.24725, 0.2245, 0.0645),
           (0.34615, 0.3143, 0.0903),
           (0.797357, 0.723991, 0.208006), 83.2),
    Preset("pewter",
           (0.105882, 0.058824, 0.113725),
           (0.427451, 0.470588, 0.541176),
           (0.333333, 0.333333, 0.521569), 9.84615),
    Preset("silver",
           _grey(0.19225),
           _grey(0.50754),
           _grey(0.508273), 51.2),
    Preset("polished_silver",
           _grey(0.23125),
           _grey(0.2775),
           _grey(0.773911), 89.6),
    # --- Gems and stones (the table's alphas, 0.55..0.95, are dropped) ---
    Preset("emerald",
           (0.0215, 0.1745, 0.0215),
           (0.07568, 0.61424, 0.07568),
           (0.633, 0.727811, 0.633), 76.8),
    Preset("jade",
           (0.135, 0.2225, 0.1575),
           (0.54, 0.89, 0.63),
           _grey(0.316228), 12.8),
    Preset("obsidian",
           (0.05375, 0.05, 0.06625),
           (0.18275, 0.17, 0.22525),
           (0.332741, 0.328634, 0.346435), 38.4),
    Preset("pearl",
           (0.25, 0.20725, 0.20725),
           (1.0, 0.829, 0.829),
           _grey(0.296648), 11.264),
    Preset("ruby",
           (0.1745, 0.01175, 0.01175),
           (0.61424, 0.04136, 0.04136),
           (0.727811, 0.626959, 0.626959), 76.8),
    Preset("turquoise",
           (0.1, 0.18725, 0.1745),
           (0.396, 0.74151, 0.69102),
           (0.297254, 0.30829, 0.306678), 12.8),
    # --- The black plastic and black rubber of the SIGGRAPH table ---
    Preset("black_plastic",
           _grey(0.0),
           _grey(0.01),
           _grey(0.5), 32.0),
    Preset("black_rubber",
           _grey(0.02),
           _grey(0.01),
           _grey(0.4), 10.0),
    # --- Coloured plastics (teapots.c / Devernay; shininess 0.25 * 128) ---
    Preset("cyan_plastic",
           (0.0, 0.1, 0.06),
           (0.0, 0.50980392, 0.50980392),
           _grey(0.50196078), 32.0),
    Preset("green_plastic",
           _grey(0.0),
           (0.1, 0.35, 0.1),
           (0.45, 0.55, 0.45), 32.0),
    Preset("red_plastic",
           _grey(0.0),
           (0.5, 0.0, 0.0),
           (0.7, 0.6, 0.6), 32.0),
    Preset("white_plastic",
           _grey(0.0),
           _grey(0.55),
           _grey(0.7), 32.0),
    Preset("yellow_plastic",
           _grey(0.0),
           (0.5, 0.5, 0.0),
           (0.6, 0.6, 0.5), 32.0),
    # --- Coloured rubbers (teapots.c / Devernay; shininess 0.078125 * 128) ---
    Preset("cyan_rubber",
           (0.0, 0.05, 0.05),
           (0.4, 0.5, 0.5),
           (0.04, 0.7, 0.7), 10.0),
    Preset("green_rubber",
           (0.0, 0.05, 0.0),
           (0.4, 0.5, 0.4),
           (0.04, 0.7, 0.04), 10.0),
    Preset("red_rubber",
           (0.05, 0.0, 0.0),
           (0.5, 0.4, 0.4),
           (0.7, 0.04, 0.04), 10.0),
    Preset("white_rubber",
           _grey(0.05),
           _grey(0.5),
           _grey(0.7), 10.0),
    Preset("yellow_rubber",
           (0.05, 0.05, 0.0),
           (0.5, 0.5, 0.4),
           (0.7, 0.7, 0.04), 10.0),
]

PRESETS: dict[str, Preset] = {p.name: p for p in _TABLE}


def preset(name: str) -> Preset:
    """The preset called `name`; KeyError naming the known ones otherwise."""
    try:
        return PRESETS[name]
    except KeyError:
        known = ", ".join(PRESETS)
        raise KeyError(f"unknown material preset {name!r} (known: {known})") from None


def _num(x: float) -> str:
    # The digits as printed in the source (at most 8 decimals, for the
    # plastics' n/255 values), without trailing-zero noise: 0.5, 32, 0.0695701.
    return f"{x:.8f}".rstrip("0").rstrip(".")


def _rgb(c: RGB) -> str:
    return " ".join(_num(v) for v in c)


def table_rows() -> list[str]:
    """Aligned text lines for `rtcli presets`: a header, then one row per preset."""
    header = ("name", "ambient", "diffuse", "specular", "shininess")
    cells = [
        (p.name, _rgb(p.ambient), _rgb(p.diffuse), _rgb(p.specular), _num(p.shininess))
        for p in PRESETS.values()
    ]
    widths = [max(len(r[i]) for r in [header, *cells]) for i in range(len(header))]

    def line(row: tuple[str, ...]) -> str:
        left = [cell.ljust(w) for cell, w in zip(row[:-1], widths[:-1])]
        return "  ".join([*left, row[-1].rjust(widths[-1])]).rstrip()

    return [line(header), *(line(r) for r in cells)]
