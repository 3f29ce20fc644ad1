"""Old home of the readers, kept for the Python API's ``fuzzoff.sources.base`` import (README);
the formats live in ``fuzzoff.formats``, the shared types in ``fuzzoff.recording``."""
