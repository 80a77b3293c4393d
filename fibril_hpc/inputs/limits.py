"""Limits checked before any work starts: grid size, memory of one scene, job count.

Every check raises a :class:`~fibril_hpc.errors.ConfigError` (one line, exit status 2) from the
validation of ``fibril-run``, ``fibril-campaign run`` and ``--dry-run`` alike, before an
operator is built or a job is enumerated.

Memory model: one ``simulate`` call holds the FFT operator and its work arrays on the padded
m x m grid plus per-element solver vectors; the peak resident memory measured on this machine
grew by 54 and 41 bytes per m^2 (m = 2160: +253 MB, m = 3840: +607 MB, ``simulate`` of one
preload; ``python benchmarks/scene_memory.py 40 12`` and ``60 14``, 2026-11-23; 59 and 56 before
the FFT pair's column stage ran in blocks and stopped holding three m x (m/2+1) spectra).
The estimate is :data:`BYTES_PER_FFT_ELEMENT` (that, plus a margin) x m^2 +
:data:`BASE_BYTES`, plus the two-level preconditioner's coarse level where it is used
(``solver.preconditioner`` ``auto``, ``two_level`` or ``moments`` on at most
``coarse.MAX_PILLARS`` pillars): :func:`coarse_bytes` or :func:`moment_bytes`, dense
pillar x pillar arrays that grow with n_side^4, not with the grid.
It is compared with the memory available now (``MemAvailable`` of
``/proc/meminfo``, or a cgroup's limit when lower); ``--ignore-memory-check`` runs anyway.
"""

from __future__ import annotations

from ..elastic.greens import padded_size
from ..errors import ConfigError
from ..geometry.grid import Lattice
from ..solve.coarse import MAX_PILLARS
from ..solve.factory import prefers_moments

#: largest grid side (elements) of a scene
MAX_GRID_SIDE = 8192
#: most jobs of one campaign grid
MAX_JOBS = 10_000_000
#: peak bytes per element of the padded FFT grid (41-54 measured, see the module docstring)
BYTES_PER_FFT_ELEMENT = 72
#: the interpreter, numba, FFTW and the libraries
BASE_BYTES = 128 << 20


def check_grid(n_side: int, phi: float, elements_per_diameter: float,
               lattice: str = "square") -> int:
    """The grid side of the scene's lattice, or a ConfigError when it exceeds
    :data:`MAX_GRID_SIDE`."""
    n = Lattice.of(n_side, phi, elements_per_diameter, lattice).grid_side
    if n > MAX_GRID_SIDE:
        raise ConfigError("elements_per_diameter", elements_per_diameter,
                          f"a resolution giving at most {MAX_GRID_SIDE} elements per side "
                          f"(this one gives {n} for n_side={n_side}, lattice {lattice})")
    return n


#: pillar x pillar float64 arrays of the coarse level: two kept (the point-force couplings and
#: F^-1), one copy of F^-1 while a preload snapshot is taken ahead (loading.PathDriver), and at
#: most four alive during an update (a rank-one product, or a dense rebuild's matrix, LAPACK's
#: two work copies and the symmetrised inverse)
COARSE_SQUARE_ARRAYS = 7
#: bytes per active element of the coarse level: Z (float64), the attached set it was built on
#: (uint8) and the indicator of that set (float64, during an update)
COARSE_BYTES_PER_ELEMENT = 17
#: pillar-length float64 vectors of the coarse level (W, 1/W, Z^T r and temporaries)
COARSE_PILLAR_VECTORS = 8


def coarse_bytes(n_pillars: int, n_active: int) -> int:
    """Peak bytes of the two-level preconditioner's coarse level (:mod:`fibril_hpc.solve.coarse`) on
    ``n_pillars`` pillars with ``n_active`` active elements (its block-Jacobi level not
    included: block Jacobi alone holds that too)."""
    return (8 * (COARSE_SQUARE_ARRAYS * n_pillars + COARSE_PILLAR_VECTORS) * n_pillars
            + COARSE_BYTES_PER_ELEMENT * n_active)


#: (3 n_pillars)^2 float64 arrays of the moment coarse level: three kept (the multipole
#: couplings, F^-1 and the update work space), one copy of F^-1 while a preload snapshot is taken
#: ahead, at most four alive during a dense rebuild (the matrix, LAPACK's two work copies and the
#: symmetrised inverse)
MOMENT_SQUARE_ARRAYS = 8
#: bytes per active element of the moment level: the unit-moment shapes and the moment columns
#: of an update (3 float64 each), the attached set it was built on (uint8)
MOMENT_BYTES_PER_ELEMENT = 49


def moment_bytes(n_pillars: int, n_active: int) -> int:
    """Peak bytes of the moment coarse level (:mod:`fibril_hpc.solve.moments`) on ``n_pillars``
    pillars with ``n_active`` active elements (its block-Jacobi level not included)."""
    return (8 * MOMENT_SQUARE_ARRAYS * (3 * n_pillars)**2 + 8 * 64 * n_pillars
            + MOMENT_BYTES_PER_ELEMENT * n_active)


def uses_coarse_level(scene) -> bool:
    """Whether ``scene``'s solver builds a coarse level (``auto``, ``two_level`` or ``moments``
    on at most ``coarse.MAX_PILLARS`` pillars; counted whatever the footprints: an upper
    bound)."""
    return scene.solver.preconditioner in ("auto", "two_level", "moments") and \
        scene.n_side**2 <= MAX_PILLARS


def coarse_level_bytes(scene, fft_size: int, n_active: int) -> int:
    """Peak bytes of the coarse level ``scene``'s solver builds on an FFT of side ``fft_size``
    (0 when it builds none): the moment level where ``auto`` would pick it, else the force one."""
    if not uses_coarse_level(scene):
        return 0
    ng = scene.n_side**2
    kind = scene.solver.preconditioner
    if kind == "moments" or (kind == "auto" and prefers_moments(fft_size, ng)):
        return moment_bytes(ng, n_active)
    return coarse_bytes(ng, n_active)


def memory_estimate(scene) -> tuple[int, int, int]:
    """(estimated peak bytes of one ``simulate`` call, grid side, FFT side) of ``scene``."""
    n = Lattice.of(scene.n_side, scene.phi, scene.elements_per_diameter, scene.lattice).grid_side
    m = padded_size(n)
    need = BYTES_PER_FFT_ELEMENT * m * m + BASE_BYTES
    need += coarse_level_bytes(scene, m, n * n)        # n^2 bounds the active elements
    return need, n, m


def available_memory() -> int | None:
    """Bytes of memory available now (None when unknown)."""
    avail = None
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    avail = int(line.split()[1]) * 1024
                    break
    except (OSError, ValueError):
        pass
    for path in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        try:
            with open(path) as fh:
                text = fh.read().strip()
            limit = int(text)
        except (OSError, ValueError):
            continue
        if 0 < limit < (1 << 60):
            avail = limit if avail is None else min(avail, limit)
    return avail


def check_memory(scene, *, available: int | None = None, field: str = "scene") -> int:
    """The estimate, or a ConfigError when it exceeds the memory available."""
    need, n, m = memory_estimate(scene)
    avail = available_memory() if available is None else available
    if avail is not None and need > avail:
        raise ConfigError(field, f"{scene.n_side}x{scene.n_side} pillars on a {n}^2 grid "
                          f"(FFT {m}^2, about {need / 2**30:.1f} GiB per run)",
                          f"a scene that fits the {avail / 2**30:.1f} GiB of memory available "
                          "(lower n_side or elements_per_diameter), or --ignore-memory-check "
                          "to run anyway")
    return need


def check_job_count(counts: dict) -> int:
    """The product of the grid's list lengths, or a ConfigError above :data:`MAX_JOBS`
    (checked before any job is enumerated)."""
    total = 1
    for v in counts.values():
        total *= max(0, int(v))
    if total > MAX_JOBS:
        what = " x ".join(f"{v} {k}" for k, v in counts.items())
        raise ConfigError("campaign", f"{total} jobs ({what})", f"at most {MAX_JOBS:.0e} jobs")
    return total


__all__ = ["check_grid", "check_memory", "check_job_count", "memory_estimate", "coarse_bytes",
           "moment_bytes", "available_memory", "MAX_GRID_SIDE", "MAX_JOBS"]
