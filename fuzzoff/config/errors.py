"""The configuration's usage error, and the did-you-mean its messages (and the CLI's) end with.

Both live in ``fuzzoff.usage``, which the command line imports without this package (whose
``__init__`` reads the catalog and the gate model's parameters): one class, two names.
"""

from __future__ import annotations

from fuzzoff.usage import ConfigError as ConfigError
from fuzzoff.usage import did_you_mean as did_you_mean
