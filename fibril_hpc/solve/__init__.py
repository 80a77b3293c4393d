"""Solving one attached set: constrained conjugate gradients, preconditioners, local cascades.

Owns :mod:`.solver` (CG on the attached set at one plate displacement), :mod:`.precond` (the
diagonal and block-Jacobi preconditioners), the coarse levels built on block Jacobi
(:mod:`.coarse`: one force per pillar; :mod:`.moments`: force and two tilts, inverse kept
dense; :mod:`.lattice`: the same applied by FFT on the pillar lattice), :mod:`.factory`
(which preconditioner a scene gets: the only module that knows every level) and
:mod:`.cascade` (local solves on a few pillars with the far field held).

May import: :mod:`fibril_hpc.elastic`, :mod:`fibril_hpc.geometry`, :mod:`fibril_hpc.kernels`,
:mod:`fibril_hpc.errors`. Inside the layer: ``solver -> factory -> lattice -> moments -> coarse -> precond``.
"""
