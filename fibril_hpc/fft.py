"""An FFT pair (real-to-complex forward, complex-to-real backward) that owns its plans and buffers.

Two backends share one interface: ``pyfftw`` (plans built once, aligned buffers, planning effort
and thread count chosen by the caller) and ``numpy`` (reference/comparison). Both compute the
*unnormalised* pair: ``backward(forward(x)) == m*m * x``; callers fold 1/(m*m) into their
multipliers. Each object counts the pairs it executed (``n_pairs``).

Callers write straight into :attr:`real_in`, read :attr:`spectrum` / write it, and read
:attr:`real_out`. ``real_in`` is never overwritten by a transform (FFTW r2c preserves its input),
so entries a caller never touches stay zero across calls.
"""

from __future__ import annotations

import numpy as np

_EFFORT = {"estimate": "FFTW_ESTIMATE", "measure": "FFTW_MEASURE", "patient": "FFTW_PATIENT"}


class FFTPair:
    """Unnormalised 2-D real FFT pair on an (m, m) grid.

    Parameters
    ----------
    m : int
        Grid side.
    backend : {"pyfftw", "numpy"}
    threads : int
        FFT threads (pyfftw only).
    planner : {"estimate", "measure", "patient"}
        FFTW planning effort (pyfftw only).
    """

    def __init__(self, m: int, backend: str = "pyfftw", threads: int = 1, planner: str = "estimate"):
        self.m = int(m)
        self.backend = backend
        self.threads = int(threads)
        self.n_pairs = 0
        shape_c = (self.m, self.m // 2 + 1)
        if backend == "pyfftw":
            import pyfftw

            self.real_in = pyfftw.zeros_aligned((self.m, self.m), dtype=np.float64)
            self.spectrum = pyfftw.zeros_aligned(shape_c, dtype=np.complex128)
            self.real_out = pyfftw.zeros_aligned((self.m, self.m), dtype=np.float64)
            # Planning with MEASURE/PATIENT overwrites the arrays: plan first, then zero.
            flags = (_EFFORT[planner],)
            self._fwd = pyfftw.FFTW(self.real_in, self.spectrum, axes=(0, 1),
                                    direction="FFTW_FORWARD", flags=flags, threads=self.threads)
            self._bwd = pyfftw.FFTW(self.spectrum, self.real_out, axes=(0, 1),
                                    direction="FFTW_BACKWARD",
                                    flags=flags + ("FFTW_DESTROY_INPUT",), threads=self.threads)
            self.real_in[...] = 0.0
            self.spectrum[...] = 0.0
            self.real_out[...] = 0.0
        elif backend == "numpy":
            self.real_in = np.zeros((self.m, self.m))
            self.spectrum = np.zeros(shape_c, dtype=np.complex128)
            self.real_out = np.zeros((self.m, self.m))
            self._fwd = self._bwd = None
        else:
            raise ValueError(f"unknown FFT backend {backend!r}")

    def forward(self) -> None:
        """spectrum <- rfft2(real_in) (unnormalised)."""
        if self._fwd is not None:
            self._fwd.execute()
        else:
            self.spectrum[...] = np.fft.rfft2(self.real_in)

    def backward(self) -> None:
        """real_out <- unnormalised irfft2(spectrum); the spectrum is destroyed."""
        if self._bwd is not None:
            self._bwd.execute()
        else:
            self.real_out[...] = np.fft.irfft2(self.spectrum, s=(self.m, self.m), norm="forward")
        self.n_pairs += 1

    @staticmethod
    def library_versions() -> dict:
        """Versions of pyFFTW and the FFTW it wraps (empty strings when unavailable)."""
        out = {"pyfftw": "", "fftw": ""}
        try:
            import pyfftw

            out["pyfftw"] = getattr(pyfftw, "__version__", "")
            ver = getattr(pyfftw, "fftw_version", "")
            out["fftw"] = ver.decode() if isinstance(ver, bytes) else str(ver)
        except ImportError:  # pragma: no cover
            pass
        return out
