"""The version, in one place: hatchling reads it for the package metadata, and fuzzoff needs
no ``importlib.metadata`` lookup at start-up (about 0.1 s of CPU on every run)."""

__version__ = "0.1.0"
