"""The zero-padded convolution engine: an FFT pair that owns its plans and buffers.

The padded m x m input is zero outside the rows that hold elements that can touch (pillar rows:
about 45 % of the N rows of a brush at phi = 0.16, and the padding doubles m), and only those rows
of the output are read. The ``pyfftw`` backend therefore prunes the row stage of the 2-D real
transform: r2c along x on the R active rows only, c2c along y on every column, multiply by the
(real) kernel transform, inverse c2c along y, c2r along x on the R active rows only. That is about
half of the full 2-D work (measurements: ``benchmarks/NOTES.md``).

The ``numpy`` backend is the float64 reference: the plain full ``rfft2``/``irfft2`` of the padded
array. Both are unnormalised (callers fold 1/(m*m) into the kernel transform) and count the pairs
they executed (``n_pairs``).

Callers write the active values into :attr:`real_in` (shape (R, m); entries never written stay
zero), call :meth:`convolve`, and read :attr:`real_out` (shape (R, m)).
"""

from __future__ import annotations

import numpy as np

_EFFORT = {"estimate": "FFTW_ESTIMATE", "measure": "FFTW_MEASURE", "patient": "FFTW_PATIENT"}


class FFTPair:
    """Pruned, unnormalised 2-D real convolution on an (m, m) grid.

    Parameters
    ----------
    m : int
        Padded grid side.
    rows : array of int
        Sorted rows of the padded grid that carry input and whose output is read.
    backend : {"pyfftw", "numpy"}
    threads : int
        FFT threads (pyfftw only).
    planner : {"estimate", "measure", "patient"}
        FFTW planning effort (pyfftw only).
    """

    def __init__(self, m: int, rows, backend: str = "pyfftw", threads: int = 1,
                 planner: str = "estimate"):
        self.m = int(m)
        self.rows = np.asarray(rows, dtype=np.int64)
        self.backend = backend
        self.threads = int(threads)
        self.n_pairs = 0
        self._kernel_src = None
        self._kernel_ri = None
        r, w = len(self.rows), self.m // 2 + 1
        if backend == "pyfftw":
            import pyfftw

            z = pyfftw.zeros_aligned
            self.real_in = z((r, self.m), dtype=np.float64)
            self._rows_hat = z((r, w), dtype=np.complex128)
            self._full = z((self.m, w), dtype=np.complex128)
            self._spec = z((self.m, w), dtype=np.complex128)
            self._prod = z((self.m, w), dtype=np.complex128)
            self._rows_back = z((r, w), dtype=np.complex128)
            self.real_out = z((r, self.m), dtype=np.float64)
            flags = (_EFFORT[planner],)
            kw = dict(flags=flags, threads=self.threads)
            self._p1 = pyfftw.FFTW(self.real_in, self._rows_hat, axes=(1,), **kw)
            self._p2 = pyfftw.FFTW(self._full, self._spec, axes=(0,), **kw)
            # out of place (product buffer -> spectrum buffer): FFTW's in-place column transform
            # copies every column through a buffer
            self._p3 = pyfftw.FFTW(self._prod, self._spec, axes=(0,), direction="FFTW_BACKWARD",
                                   flags=flags + ("FFTW_DESTROY_INPUT",), threads=self.threads)
            # real views (re, im interleaved) for the multiply by the real kernel transform
            self._spec_ri = self._spec.view(np.float64).reshape(self.m, w, 2)
            self._prod_ri = self._prod.view(np.float64).reshape(self.m, w, 2)
            self._p4 = pyfftw.FFTW(self._rows_back, self.real_out, axes=(1,),
                                   direction="FFTW_BACKWARD",
                                   flags=flags + ("FFTW_DESTROY_INPUT",), threads=self.threads)
            # planning with MEASURE/PATIENT scribbles on the arrays: zero them afterwards
            for a in (self.real_in, self._rows_hat, self._full, self._spec, self._prod,
                      self._rows_back, self.real_out):
                a[...] = 0
        elif backend == "numpy":
            self.real_in = np.zeros((r, self.m))
            self.real_out = np.zeros((r, self.m))
            self._padded = np.zeros((self.m, self.m))
        else:
            raise ValueError(f"unknown FFT backend {backend!r}")

    def work_arrays(self) -> dict:
        """The buffers this pair owns, by name (for read-only use, e.g. memory accounting): not
        the real views of its own complex buffers (``_spec_ri``, ``_prod_ri``) nor the caller's
        kernel transform (``_kernel_src``); the real kernel copy ``_kernel_ri`` once it exists."""
        skip = ("rows", "_spec_ri", "_prod_ri", "_kernel_src")
        return {k: v for k, v in vars(self).items() if isinstance(v, np.ndarray) and k not in skip}

    def stages(self, kernel_hat: np.ndarray) -> dict:
        """The stages of one pyfftw product, in order, as named callables (for timing them one by
        one; running all of them in order is :meth:`convolve` without the pair count)."""
        if self.backend != "pyfftw":
            raise ValueError("stages exist for the pyfftw backend only")
        return {
            "p1 r2c rows": self._p1.execute,
            "scatter rows": lambda: self._full.__setitem__(self.rows, self._rows_hat),
            "p2 c2c cols": self._p2.execute,
            "multiply": lambda: np.multiply(self._spec_ri, self._real_kernel(kernel_hat),
                                            out=self._prod_ri),
            "p3 c2c cols inv": self._p3.execute,
            "gather rows": lambda: np.take(self._spec, self.rows, axis=0, out=self._rows_back),
            "p4 c2r rows": self._p4.execute,
        }

    def _real_kernel(self, kernel_hat: np.ndarray) -> np.ndarray:
        """The real kernel transform duplicated per (re, im), made once per kernel: a plain
        contiguous float64 multiply, measured faster than the complex one and a broadcast one."""
        if self._kernel_src is not kernel_hat:
            self._kernel_ri = np.repeat(np.asarray(kernel_hat, np.float64)[:, :, None], 2, axis=2)
            self._kernel_src = kernel_hat
        return self._kernel_ri

    def convolve(self, kernel_hat: np.ndarray) -> None:
        """real_out <- rows of irfft2(rfft2(padded real_in) * kernel_hat), unnormalised.

        ``kernel_hat`` is real, shape (m, m//2 + 1); it is multiplied into the real and imaginary
        parts as float64 (no complex copy of the kernel per call)."""
        if self.backend == "pyfftw":
            self._p1.execute()
            self._full[self.rows] = self._rows_hat
            self._p2.execute()
            np.multiply(self._spec_ri, self._real_kernel(kernel_hat), out=self._prod_ri)
            self._p3.execute()
            np.take(self._spec, self.rows, axis=0, out=self._rows_back)
            self._p4.execute()
        else:
            self._padded[self.rows] = self.real_in
            spec = np.fft.rfft2(self._padded)
            spec *= kernel_hat
            out = np.fft.irfft2(spec, s=(self.m, self.m), norm="forward")
            self.real_out[...] = out[self.rows]
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
