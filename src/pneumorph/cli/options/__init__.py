"""What many commands parse.

Checked parameter types (:mod:`~pneumorph.cli.options.params`), where designs are solved
(:mod:`~pneumorph.cli.options.execution`) and the design goals given as options
(:mod:`~pneumorph.cli.options.targets`).
"""
