"""The effects catalogue: each effect's equations (through the sympy ``Context``), stable numeric forms
and force law, with the integrator and the run records that force laws write into."""
