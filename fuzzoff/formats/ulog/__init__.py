"""PX4 ULogs: reader (pyulog), the damage checks around it, topic decoders and writer."""
