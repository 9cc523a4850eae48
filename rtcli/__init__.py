"""rtcli: a Whitted ray tracer driven by YAML scene files, as a command line and a Python API.

    import rtcli
    image = rtcli.render("scenes/whitted.yaml", width=320)    # a numpy array; shows itself in Jupyter

The API (docs/python-api.md) is imported on first use, so `import rtcli` stays cheap
for the command line. `rtcli.render` is the API's function; the tile renderer it
drives is the module of the same name, imported as `from rtcli.rendering.tiles import ...`.
"""

import importlib
import sys
import types

__version__ = "0.1.0"

_EXPORTS = {
    "load_scene": "rtcli.api", "render": "rtcli.api", "signature": "rtcli.api", "view": "rtcli.api",
    "explain": "rtcli.api", "legend": "rtcli.api.pictures", "LegendRow": "rtcli.api.pictures",
    "Scene": "rtcli.api.scene", "ImageArray": "rtcli.api.results", "RenderStats": "rtcli.api.results",
    "diff": "rtcli.compare.difference", "Difference": "rtcli.compare.difference", "RtcliError": "rtcli.errors",
    "SceneError": "rtcli.errors", "RtcliWarning": "rtcli.errors",
}
__all__ = ["__version__", *_EXPORTS]


def __getattr__(name: str):
    """The API's names, imported when first asked for (PEP 562)."""
    if name not in _EXPORTS:
        raise AttributeError(f"module 'rtcli' has no attribute {name!r}")
    value = getattr(importlib.import_module(_EXPORTS[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list:
    return sorted(__all__)


class _Package(types.ModuleType):
    """This package, whose API names win over submodules of the same name: importing a submodule
    sets the package's attribute of that name (rtcli.rendering.tiles the module would hide rtcli.rendering.tiles
    the function); here that attribute is left to the API. The submodule stays in sys.modules."""

    def __setattr__(self, name, value):
        if name in _EXPORTS and isinstance(value, types.ModuleType):
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package
