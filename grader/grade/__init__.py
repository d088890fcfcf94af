"""Grading: submissions read from CSV, cells parsed safely, compared to key.json with tolerance and
units, each verdict explained, and written as grades, details, problems and a Canvas import."""
