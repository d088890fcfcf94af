"""grader: problem generator and auto-grader for engineering dynamics (impact problems)."""

__version__ = "0.2.0"
