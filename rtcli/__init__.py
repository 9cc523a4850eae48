"""rtcli: a command-line Whitted ray tracer driven by YAML scene files."""

__version__ = "0.1.0"
