"""The data every stage shares: safe expressions and their numpy evaluation, exact units, and the
frozen scene types (bodies, stages). Imports nothing of grader but ``errors``."""
