"""MAVLink telemetry logs (.tlog): reader, packet framing and writer."""
