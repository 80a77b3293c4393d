"""The elastic half-space: Love's influence coefficients, the zero-padded FFT convolution
engine, the non-periodic Boussinesq operator, and closed-form half-space contact solutions.

Owns :mod:`.greens` (Love's coefficients, the transformed kernel), :mod:`.fft` (an FFT pair
that owns its pyFFTW plans and buffers), :mod:`.halfspace` (u = K * p on the elements that can
touch) and :mod:`.analytic` (Kendall, JKR, Hertz, punch stiffness: the references the tests and
the footprint criterion use).

May import: :mod:`fibril_hpc.geometry`, :mod:`fibril_hpc.kernels`, :mod:`fibril_hpc.errors`.
"""
