"""Assignments: the assignment file and roster, one seeded variant per student rounded as printed, and
the key files (key.json, key.csv) that grading reads."""
