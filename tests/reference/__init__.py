"""Independent reference computations used by the tests only (never by a run)."""
