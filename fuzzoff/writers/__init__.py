"""Writers: normalised events -> real recordings, through each format's own library.

``fuzzoff/writers/<format>.py`` exposes ``write_<format>(path, events, **options)``. The corpus
builders, the tests and the fuzzer's reproducers all go through these, so what fuzzoff reads back
from a written recording is the stream that was written (the round-trip property).
"""
