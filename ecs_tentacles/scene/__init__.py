"""Reading, validating and describing scene files."""
