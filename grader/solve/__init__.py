"""Closed-form answers: a template's scene becomes a chain of solved steps (sympy, once), rewritten into
stable forms, compiled to numpy kernels, cached on disk, and evaluated over whole columns."""
