"""The commands of a cast actuator: its parts and moulds (``export``), its scans against the
model (``correlate``), and the model fitted to them (``identify``)."""
