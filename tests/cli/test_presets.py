"""Tests for rtcli.scenefile.presets, the McReynolds/Blythe material table."""

import dataclasses

import pytest

from rtcli.scenefile.presets import PRESETS, Preset, preset, table_rows

NAMES = [
    "brass", "bronze", "polished_bronze", "chrome", "copper", "polished_copper",
    "gold", "polished_gold", "pewter", "silver", "polished_silver",
    "emerald", "jade", "obsidian", "pearl", "ruby", "turquoise",
    "black_plastic", "black_rubber",
    "cyan_plastic", "green_plastic", "red_plastic", "white_plastic", "yellow_plastic",
    "cyan_rubber", "green_rubber", "red_rubber", "white_rubber", "yellow_rubber",
]


def test_all_29_names_present_in_order():
    assert len(NAMES) == 29
    assert list(PRESETS) == NAMES
    for name, p in PRESETS.items():
        assert isinstance(p, Preset)
        assert p.name == name


def test_brass():
    p = preset("brass")
    assert p.ambient == (0.329412, 0.223529, 0.027451)
    assert p.diffuse == (0.780392, 0.568627, 0.113725)
    assert p.specular == (0.992157, 0.941176, 0.807843)
    assert p.shininess == 27.8974


def test_copper():
    p = preset("copper")
    assert p.ambient == (0.19125, 0.0735, 0.0225)
    assert p.diffuse == (0.7038, 0.27048, 0.0828)
    assert p.specular == (0.256777, 0.137622, 0.086014)
    assert p.shininess == 12.8


def test_polished_silver():
    p = preset("polished_silver")
    assert p.ambient == (0.23125,) * 3
    assert p.diffuse == (0.2775,) * 3
    assert p.specular == (0.773911,) * 3
    assert p.shininess == 89.6


def test_black_plastic():
    p = preset("black_plastic")
    assert p.ambient == (0.0, 0.0, 0.0)
    assert p.diffuse == (0.01,) * 3
    assert p.specular == (0.5,) * 3
    assert p.shininess == 32


@pytest.mark.parametrize("name", NAMES)
def test_shininess_is_an_exponent_not_a_fraction(name):
    assert PRESETS[name].shininess > 1


@pytest.mark.parametrize("name", NAMES)
def test_coefficients_are_rgb_in_unit_range(name):
    p = PRESETS[name]
    for colour in (p.ambient, p.diffuse, p.specular):
        assert isinstance(colour, tuple) and len(colour) == 3
        assert all(0.0 <= c <= 1.0 for c in colour)


def test_unknown_name_raises_key_error():
    with pytest.raises(KeyError):
        preset("unobtainium")


def test_presets_are_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        preset("gold").shininess = 1.0


def test_table_rows_header_then_one_row_per_preset():
    rows = table_rows()
    assert len(rows) == 1 + len(PRESETS)
    assert rows[0].split()[0] == "name"
    assert "shininess" in rows[0]
    for row, name in zip(rows[1:], PRESETS):
        assert row.startswith(name + " ")


def test_table_rows_print_source_numbers():
    rows = {r.split()[0]: r.split() for r in table_rows()[1:]}
    assert rows["brass"][1:] == [
        "0.329412", "0.223529", "0.027451",
        "0.780392", "0.568627", "0.113725",
        "0.992157", "0.941176", "0.807843",
        "27.8974",
    ]
    assert rows["black_plastic"][1:] == ["0"] * 3 + ["0.01"] * 3 + ["0.5"] * 3 + ["32"]
    assert rows["cyan_plastic"][5] == "0.50980392"


def test_table_rows_columns_aligned():
    rows = table_rows()
    header = rows[0]
    for title in ("ambient", "diffuse", "specular"):
        col = header.index(title)
        for row in rows[1:]:
            # every row has a value starting in the column under its title
            assert row[col - 1] == " " and row[col] != " "
