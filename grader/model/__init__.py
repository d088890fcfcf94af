"""The data every stage shares: safe expressions and their numpy evaluation, quantities (units, dimensions,
numbers, significant figures), tolerances and the frozen scene types. Imports nothing of grader but ``base``."""
