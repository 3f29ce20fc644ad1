"""One module per ``fuzzoff`` subcommand (``add_parser`` + ``run``), discovered by ``cli``."""
