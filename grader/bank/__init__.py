"""The problem bank: YAML templates read safely, their scenes checked against the effects catalogue,
and frozen into ``Template`` objects."""
