"""What many commands parse.

Checked parameter types (:mod:`~pneumorph.cli.options.params`) and where designs are solved
(:mod:`~pneumorph.cli.options.execution`).
"""
