"""The zero-padded convolution engine: an FFT pair that owns its plans and buffers.

The padded m x m input is zero outside the rows that hold elements that can touch (pillar rows:
about 45 % of the N rows of a brush at phi = 0.16, and the padding doubles m), and only those rows
of the output are read. The ``pyfftw`` backend therefore prunes the row stage of the 2-D real
transform: r2c along x on the R active rows only, then the column stage, then c2r along x on the R
active rows only. That is about half of the full 2-D work (measurements: ``benchmarks/NOTES.md``).

The column stage (c2c along y on every column, multiply by the real kernel transform, inverse
c2c along y) runs on blocks of ``COLUMN_BLOCK`` columns at a time: the R row spectra of a block
are scattered into an m x B buffer whose other rows stay zero, transformed, multiplied and
transformed back while the block sits in the core's cache, and its R active rows gathered. The
whole m x (m/2 + 1) spectrum is never held, so the stage reads and writes each number once
instead of streaming three arrays of that size through memory several times: 1.3x faster at
m = 640, 3x at m = 1280-2048 on this machine, with bitwise the same product (each column's
transform is the same FFTW transform either way).

The ``numpy`` backend is the float64 reference: the plain full ``rfft2``/``irfft2`` of the padded
array. Both are unnormalised (callers fold 1/(m*m) into the kernel transform) and count the pairs
they executed (``n_pairs``).

Callers write the active values into :attr:`real_in` (shape (R, m); entries never written stay
zero), call :meth:`convolve`, and read :attr:`real_out` (shape (R, m)).
"""

from __future__ import annotations

import numpy as np

_EFFORT = {"estimate": "FFTW_ESTIMATE", "measure": "FFTW_MEASURE", "patient": "FFTW_PATIENT"}

#: columns per block of the column stage (measured on this machine, ``benchmarks/NOTES.md``:
#: 10-14 best from m = 640 to 2048; 8 and 16 a little slower, 24 and more lose the cache)
COLUMN_BLOCK = 12


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
        self._kernel_blocks = None
        r, w = len(self.rows), self.m // 2 + 1
        b = COLUMN_BLOCK
        self.n_blocks = -(-w // b)
        wp = self.n_blocks * b              # the row spectra padded to whole blocks (zeros)
        if backend == "pyfftw":
            import pyfftw

            z = pyfftw.zeros_aligned
            self.real_in = z((r, self.m), dtype=np.float64)
            self._rows_hat = z((r, wp), dtype=np.complex128)
            self._col_in = z((self.m, b), dtype=np.complex128)     # rows off the R stay zero
            self._col_hat = z((self.m, b), dtype=np.complex128)
            self._col_out = z((self.m, b), dtype=np.complex128)
            self._rows_back = z((r, wp), dtype=np.complex128)
            self.real_out = z((r, self.m), dtype=np.float64)
            flags = (_EFFORT[planner],)
            kw = dict(flags=flags, threads=self.threads)
            self._p1 = pyfftw.FFTW(self.real_in, self._rows_hat[:, :w], axes=(1,), **kw)
            # out of place, so the zero rows of the block's input stay zero
            self._p2 = pyfftw.FFTW(self._col_in, self._col_hat, axes=(0,), **kw)
            self._p3 = pyfftw.FFTW(self._col_hat, self._col_out, axes=(0,),
                                   direction="FFTW_BACKWARD", **kw)
            # real view (re, im interleaved) for the multiply by the real kernel transform
            self._hat_ri = self._col_hat.view(np.float64).reshape(self.m, b, 2)
            self._p4 = pyfftw.FFTW(self._rows_back[:, :w], self.real_out, axes=(1,),
                                   direction="FFTW_BACKWARD",
                                   flags=flags + ("FFTW_DESTROY_INPUT",), threads=self.threads)
            # planning with MEASURE/PATIENT scribbles on the arrays: zero them afterwards
            for a in (self.real_in, self._rows_hat, self._col_in, self._col_hat, self._col_out,
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
        the real view of its own block buffer (``_hat_ri``) nor the caller's kernel transform
        (``_kernel_src``); the blocked real kernel copy ``_kernel_blocks`` once it exists."""
        skip = ("rows", "_hat_ri", "_kernel_src")
        return {k: v for k, v in vars(self).items() if isinstance(v, np.ndarray) and k not in skip}

    def stages(self, kernel_hat: np.ndarray) -> dict:
        """The stages of one pyfftw product, in order, as named callables (for timing them one by
        one; running all of them in order is :meth:`convolve` without the pair count)."""
        if self.backend != "pyfftw":
            raise ValueError("stages exist for the pyfftw backend only")
        return {
            "p1 r2c rows": self._p1.execute,
            "column blocks": lambda: self._columns(self._real_kernel(kernel_hat)),
            "p4 c2r rows": self._p4.execute,
        }

    def _real_kernel(self, kernel_hat: np.ndarray) -> np.ndarray:
        """The real kernel transform cut into the column blocks and duplicated per (re, im),
        shape (n_blocks, m, B, 2), made once per kernel (zero on the padding columns): a plain
        contiguous float64 multiply per block, no complex copy of the kernel per call."""
        if self._kernel_src is not kernel_hat:
            m, b = self.m, COLUMN_BLOCK
            k = np.zeros((m, self.n_blocks * b))
            k[:, :kernel_hat.shape[1]] = kernel_hat
            k = k.reshape(m, self.n_blocks, b).transpose(1, 0, 2)
            self._kernel_blocks = np.ascontiguousarray(np.repeat(k[..., None], 2, axis=3))
            self._kernel_src = kernel_hat
        return self._kernel_blocks

    def _columns(self, kernel_blocks) -> None:
        """The column stage, block by block: _rows_hat -> _rows_back."""
        b, rows = COLUMN_BLOCK, self.rows
        for i in range(self.n_blocks):
            cols = slice(i * b, (i + 1) * b)
            self._col_in[rows] = self._rows_hat[:, cols]
            self._p2.execute()
            np.multiply(self._hat_ri, kernel_blocks[i], out=self._hat_ri)
            self._p3.execute()
            self._rows_back[:, cols] = self._col_out[rows]

    def convolve(self, kernel_hat: np.ndarray) -> None:
        """real_out <- rows of irfft2(rfft2(padded real_in) * kernel_hat), unnormalised.

        ``kernel_hat`` is real, shape (m, m//2 + 1); it is multiplied into the real and imaginary
        parts as float64 (no complex copy of the kernel per call)."""
        if self.backend == "pyfftw":
            self._p1.execute()
            self._columns(self._real_kernel(kernel_hat))
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
