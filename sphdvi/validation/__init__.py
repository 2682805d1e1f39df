"""Validation helpers: reference data and error measures shared by tests/validation and tools/."""
