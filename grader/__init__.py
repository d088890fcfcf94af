"""grader: problem generator and auto-grader for engineering dynamics (impact problems)."""

__version__ = "0.1.0"
