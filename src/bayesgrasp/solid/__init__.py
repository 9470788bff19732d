"""Solid parts: meshes in, their resting poses on a table, and strategies over the poses.

:mod:`.mesh` reads and checks mesh files (STL, OBJ, PLY, 3MF, GLB; extra ``mesh``);
:mod:`.poses` finds the stable resting poses and their probabilities (the quasi-static
estimator of Goldberg et al., *Part pose statistics*, 1999, exact to rounding, and its
perturbed form) and each pose's footprint; :mod:`.parts` makes each pose a planar part;
:mod:`.policy` plans the policy that tells the poses apart by their widths; :mod:`.topple`
finds the squeezes that tip a pose over (statics of the first jaw's push).
"""
