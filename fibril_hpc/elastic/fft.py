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

from ..kernels import compiled as kern

_EFFORT = {"estimate": "FFTW_ESTIMATE", "measure": "FFTW_MEASURE", "patient": "FFTW_PATIENT"}

#: columns per block of the column stage (measured on this machine, ``benchmarks/NOTES.md``:
#: 10-14 best from m = 640 to 2048; 8 and 16 a little slower, 24 and more lose the cache)
COLUMN_BLOCK = 12


class _Lane:
    """One thread's share of an FFT pair: the active rows ``first:stop`` of the two row stages
    (r2c and c2r along x, single-threaded plans on those rows), and for the column stage an
    m x B block buffer (rows off the active ones stay zero), its spectrum and inverse, and
    single-threaded plans between them."""

    def __init__(self, pair, first: int, stop: int, flags: tuple):
        import pyfftw

        m, b, w = pair.m, COLUMN_BLOCK, pair.m // 2 + 1
        rows = slice(first, stop)
        self.p1 = pyfftw.FFTW(pair.real_in[rows], pair._rows_hat[rows, :w], axes=(1,),
                              flags=flags, threads=1)
        self.p4 = pyfftw.FFTW(pair._rows_back[rows, :w], pair.real_out[rows], axes=(1,),
                              direction="FFTW_BACKWARD", flags=flags + ("FFTW_DESTROY_INPUT",),
                              threads=1)
        z = pyfftw.zeros_aligned
        self.col_in = z((m, b), dtype=np.complex128)
        self.col_hat = z((m, b), dtype=np.complex128)
        self.col_out = z((m, b), dtype=np.complex128)
        # out of place, so the zero rows of the block's input stay zero
        self.p2 = pyfftw.FFTW(self.col_in, self.col_hat, axes=(0,), flags=flags, threads=1)
        self.p3 = pyfftw.FFTW(self.col_hat, self.col_out, axes=(0,), direction="FFTW_BACKWARD",
                              flags=flags, threads=1)
        # real view (re, im interleaved) for the multiply by the real kernel transform
        self.hat_ri = self.col_hat.view(np.float64).reshape(m, b, 2)
        for a in (self.col_in, self.col_hat, self.col_out):
            a[...] = 0

    def buffers(self) -> dict:
        """The lane's own arrays (not the real view of its spectrum)."""
        return {"col_in": self.col_in, "col_hat": self.col_hat, "col_out": self.col_out}

    def run(self, pair, kernel_blocks, first: int, stop: int) -> None:
        """Blocks ``first`` to ``stop - 1`` of ``pair``'s column stage."""
        b, rows = COLUMN_BLOCK, pair.rows
        src, dst = pair._rows_hat, pair._rows_back
        for i in range(first, stop):
            cols = slice(i * b, (i + 1) * b)
            self.col_in[rows] = src[:, cols]
            self.p2.execute()
            kern.scale_block(self.hat_ri, kernel_blocks[i])
            self.p3.execute()
            dst[:, cols] = self.col_out[rows]


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
        self._kernel = None                     # the numpy backend's loaded kernel
        r, w = len(self.rows), self.m // 2 + 1
        b = COLUMN_BLOCK
        self.n_blocks = -(-w // b)
        wp = self.n_blocks * b              # the row spectra padded to whole blocks (zeros)
        if backend == "pyfftw":
            import pyfftw

            z = pyfftw.zeros_aligned
            self.real_in = z((r, self.m), dtype=np.float64)
            self._rows_hat = z((r, wp), dtype=np.complex128)
            # the column stage writes each block's columns back where it read them, so the
            # inverse row stage reads the same array (one R x m/2 complex buffer less)
            self._rows_back = self._rows_hat
            self.real_out = z((r, self.m), dtype=np.float64)
            flags = (_EFFORT[planner],)
            # every plan is single-threaded: with fft_threads = T > 1 the pair's work is shared
            # out between T lanes in threads of our own (rows of the two row stages, blocks of
            # the column stage). FFTW's own threads (OpenMP in the pyFFTW wheels) spin between
            # the many short transforms and made the default scene 3-4x slower
            # (benchmarks/NOTES.md)
            n_lanes = max(1, min(self.threads, self.n_blocks, r))
            cuts = np.linspace(0, r, n_lanes + 1).round().astype(int)
            self._lanes = [_Lane(self, int(a), int(e), flags) for a, e in zip(cuts[:-1], cuts[1:])]
            self._pool = None
            # planning with MEASURE/PATIENT scribbles on the arrays: zero them afterwards
            for a in (self.real_in, self._rows_hat, self.real_out):
                a[...] = 0
        elif backend == "numpy":
            self.real_in = np.zeros((r, self.m))
            self.real_out = np.zeros((r, self.m))
            self._padded = np.zeros((self.m, self.m))
        else:
            raise ValueError(f"unknown FFT backend {backend!r}")

    def work_arrays(self) -> dict:
        """The buffers this pair owns, by name (for read-only use, e.g. memory accounting): not
        the caller's kernel transform (``_kernel_src``); its copy cut into the column blocks
        (``_kernel_blocks``) once loaded or once a product has made it; each column lane's
        block buffers."""
        skip = ("rows", "_kernel_src", "_rows_back")     # _rows_back is _rows_hat
        out = {k: v for k, v in vars(self).items() if isinstance(v, np.ndarray) and k not in skip}
        for i, lane in enumerate(getattr(self, "_lanes", ())):
            out.update({f"lane{i}_{k}": v for k, v in lane.buffers().items()})
        return out

    def stages(self, kernel_hat: np.ndarray | None = None) -> dict:
        """The stages of one pyfftw product, in order, as named callables (for timing them one by
        one; running all of them in order is :meth:`convolve` without the pair count). The
        column stage transforms the row spectra in place: called twice without the row stage
        between, it multiplies by the kernel twice."""
        if self.backend != "pyfftw":
            raise ValueError("stages exist for the pyfftw backend only")
        return {
            "p1 r2c rows": self._rows_forward,
            "column blocks": lambda: self._columns(self._blocked(kernel_hat)),
            "p4 c2r rows": self._rows_backward,
        }

    def load_kernel(self, kernel_hat: np.ndarray) -> None:
        """Keep ``kernel_hat`` (real, (m, m//2 + 1)) as the pair's own kernel, for
        :meth:`convolve` called without one: cut into the column blocks (pyfftw) with no
        reference to the caller's array kept, so that the caller may drop it and the kernel is
        held once (4 bytes per m^2; the numpy backend keeps the array itself)."""
        if self.backend == "pyfftw":
            self._blocked(kernel_hat)
            self._kernel_src = None
        else:
            self._kernel = kernel_hat

    def kernel_transform(self) -> np.ndarray:
        """The loaded kernel as one (m, m//2 + 1) array: a new copy from the column blocks
        (pyfftw; 4 bytes per m^2 while it lives), the kept array itself (numpy)."""
        k = self._loaded()
        if self.backend != "pyfftw":
            return k
        return np.ascontiguousarray(k.transpose(1, 0, 2).reshape(self.m, -1)[:, :self.m // 2 + 1])

    def _loaded(self) -> np.ndarray:
        """The kernel as kept: the column blocks (pyfftw) or the array (numpy)."""
        k = self._kernel_blocks if self.backend == "pyfftw" else self._kernel
        if k is None:
            raise ValueError("no kernel loaded")
        return k

    def _blocked(self, kernel_hat: np.ndarray) -> np.ndarray:
        """The real kernel transform cut into the column blocks, shape (n_blocks, m, B), made
        once per kernel (zero on the padding columns), one block at a time: each block's
        multiply reads a contiguous array, into the real and imaginary parts alike. (Read in
        place from the (m, m/2 + 1) kernel, the pair was 13-25 % slower; duplicated per
        (re, im) for a plain NumPy multiply, as before, it took twice the memory for the same
        speed: benchmarks/NOTES.md, "The kernel transform built in blocks".)"""
        if kernel_hat is None:                  # the loaded kernel (load_kernel)
            return self._loaded()
        if self._kernel_src is not kernel_hat:
            m, b, w = self.m, COLUMN_BLOCK, kernel_hat.shape[1]
            self._kernel_blocks = None          # a former kernel's copy goes before the new one
            blocks = np.zeros((self.n_blocks, m, b))
            for i in range(self.n_blocks):
                c = kernel_hat[:, i * b:min((i + 1) * b, w)]
                blocks[i, :, :c.shape[1]] = c
            self._kernel_blocks = blocks
            self._kernel_src = kernel_hat
        return self._kernel_blocks

    def _columns(self, kernel_blocks) -> None:
        """The column stage, block by block, in place in _rows_hat (which is _rows_back). With
        several lanes the blocks are split into contiguous runs, one per thread (the plans
        release the GIL); each column's transform is the same either way."""
        lanes = self._lanes
        if len(lanes) == 1:
            lanes[0].run(self, kernel_blocks, 0, self.n_blocks)
            return
        edges = np.linspace(0, self.n_blocks, len(lanes) + 1).round().astype(int)
        self._in_lanes([(lane.run, (self, kernel_blocks, int(a), int(e)))
                        for lane, a, e in zip(lanes, edges[:-1], edges[1:])])

    def _rows_forward(self) -> None:
        """r2c along x of the active rows, shared between the lanes."""
        self._in_lanes([(lane.p1.execute, ()) for lane in self._lanes])

    def _rows_backward(self) -> None:
        """c2r along x of the active rows, shared between the lanes."""
        self._in_lanes([(lane.p4.execute, ()) for lane in self._lanes])

    def _in_lanes(self, calls) -> None:
        """Run ``calls`` [(fn, args)], one per lane: in this thread for one lane, else in the
        pair's own thread pool, waiting for all."""
        if len(calls) == 1:
            fn, args = calls[0]
            fn(*args)
            return
        if self._pool is None:
            from concurrent.futures import ThreadPoolExecutor

            self._pool = ThreadPoolExecutor(len(calls) - 1, thread_name_prefix="fibril-fft")
        futures = [self._pool.submit(fn, *args) for fn, args in calls[1:]]
        fn, args = calls[0]
        fn(*args)                               # the first share in the calling thread
        for f in futures:
            f.result()

    def close(self) -> None:
        """Stop the column stage's worker threads (if any); the pair still works afterwards
        (they start again on the next product)."""
        if getattr(self, "_pool", None) is not None:
            self._pool.shutdown(wait=True)
            self._pool = None

    def convolve(self, kernel_hat: np.ndarray | None = None) -> None:
        """real_out <- rows of irfft2(rfft2(padded real_in) * kernel_hat), unnormalised.

        ``kernel_hat`` is real, shape (m, m//2 + 1); it is multiplied into the real and imaginary
        parts as float64 (no complex copy of the kernel per call). None: the kernel given to
        :meth:`load_kernel`."""
        if self.backend == "pyfftw":
            self._rows_forward()
            self._columns(self._blocked(kernel_hat))
            self._rows_backward()
        else:
            if kernel_hat is None:
                kernel_hat = self._loaded()
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
