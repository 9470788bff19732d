"""Reproductions of the seed paper.

Table 1 (:mod:`.table1`) and the 2000-polygon study (:mod:`.study`). They use the library as
any user would and add nothing to the model.
"""
