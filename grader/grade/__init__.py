"""Grading: submissions read from CSV, cells parsed safely, compared to key.json with tolerance and
units, scored, explained, and written as files an LMS imports. (Empty until the grading issue.)"""
