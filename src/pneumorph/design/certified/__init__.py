"""The certified search: every design scored by the chain model, the best verified by FE, with a bound.

- :mod:`~pneumorph.design.certified.search`: the search and its certificate (the driver);
- :mod:`~pneumorph.design.certified.planning`: which search, which table, what it will build;
- :mod:`~pneumorph.design.certified.bounds`: the chain's validated errors and the bound on
  every design's objective;
- :mod:`~pneumorph.design.certified.prefixes`, :mod:`~pneumorph.design.certified.branching`,
  :mod:`~pneumorph.design.certified.planegrowth`, :mod:`~pneumorph.design.certified.spacegrowth`:
  designs grown unit by unit over shared prefixes, in the plane and in space, and the
  branch-and-bound over them;
- :mod:`~pneumorph.design.certified.reach`, :mod:`~pneumorph.design.certified.headingbox`,
  :mod:`~pneumorph.design.certified.remainder`: what the units still to place can reach, and
  the lower bound on what they add to a cost;
- :mod:`~pneumorph.design.certified.refine`: the verified designs again on a finer mesh;
- :mod:`~pneumorph.design.certified.certificate`: the certificate in words.

The names to import are re-exported by :mod:`pneumorph.design`.
"""

__all__: list[str] = []  # the names to import are re-exported by the parent package
