"""Spacetime finite-element solutions (st2005): tent-pitched simplicial meshes of space × time,
closed-form elastodynamic fields, per-element cubic polynomials in element-local coordinates,
time slicing and the exact shading of a slice. GL-free: numpy arrays in, numpy arrays out.
The slicing kernel takes its arrays grouped as the NamedTuples of :mod:`.state`."""
