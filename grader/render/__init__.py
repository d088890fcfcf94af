"""Documents: student sheets, the class PDF and the answer key with worked steps and figures to scale
(Jinja2 → Typst), and the ``generate``/``demo`` jobs that write them with the key."""
