"""Limits checked before any work starts: grid size, memory of one scene, job count.

Every check raises a :class:`~fibril_hpc.errors.ConfigError` (one line, exit status 2) from the
validation of ``fibril-run``, ``fibril-campaign run`` and ``--dry-run`` alike, before an
operator is built or a job is enumerated.

Memory model: one ``simulate`` call holds the FFT operator and its work arrays on the padded
m x m grid, the solver's per-element vectors, the coarse level of its preconditioner and one
saved state per preload of its loading path. Measured (``python benchmarks/scene_memory.py``,
scenes from m = 960 to 16 384, 32 400 to 9 million active elements, stopped after three
events, 2026-11-28, benchmarks/NOTES.md "The kernel transform built in blocks"): once the
coarse level and the preload's snapshot are taken off, the peak resident memory of the whole
process is about 160 MiB plus 14.3-19 bytes per m^2 (28-36 before the kernel transform was
built in blocks; since the kernel transform is held once, 3.4-4.0 less, benchmarks/NOTES.md
"The kernel transform held once"). Runs that go on into the unloading peak higher: the
result's pillar-state maps, the unloading branch's copies and the fixed costs grow (four
`fast` runs from 100 x 100 to 1 000 x 1 000, capped after 22-368 events, peaked at 0.79-0.91
of the estimate before the kernel was held once; a 150 x 150 one at 0.72 since).
The estimate is :data:`BASE_BYTES` + :data:`BYTES_PER_FFT_ELEMENT` (that, plus a margin) x m^2,
plus the coarse level the scene gets (``solver.preconditioner``, or what ``auto`` takes):
:func:`coarse_bytes` or :func:`moment_bytes` for the dense levels (pillar x pillar arrays that
grow with n_side^4, not with the grid), :func:`lattice_bytes` for the lattice level (linear in pillars and
elements), each on the scene's own active elements (pillars x footprint), plus
:func:`snapshot_bytes` for the preload snapshots a grouped loading path keeps, plus
:func:`state_map_bytes` for the n x n maps of the pillar states its result keeps (they grow a
run's peak past its first events).
It is compared with the memory available now: the least of ``MemAvailable`` of
``/proc/meminfo``, what the process's own cgroup (v1 or v2, found through ``/proc/self/cgroup``,
and each parent) leaves, and the address space left under ``RLIMIT_AS``;
``--ignore-memory-check`` runs anyway.
"""

from __future__ import annotations

import os
import resource

from ..elastic.greens import padded_size
from ..errors import ConfigError
from ..geometry.grid import MAX_GRID_SIDE, Lattice
from ..solve.factory import auto_kind

#: most jobs of one campaign grid
MAX_JOBS = 1_000_000
#: peak bytes per element of the padded FFT grid (14.3-19 measured, see the module docstring)
BYTES_PER_FFT_ELEMENT = 20
#: the interpreter, numba, FFTW, the libraries and a run's fixed costs: about 160 MiB in runs
#: stopped after three events, more in runs that go on into the unloading (a 100 x 100 `fast`
#: run to 368 events peaked at 491 MiB), so 320 MiB (benchmarks/NOTES.md, "The kernel transform
#: built in blocks")
BASE_BYTES = 320 << 20


def check_grid(n_side: int, phi: float, elements_per_diameter: float,
               lattice: str = "square") -> int:
    """The grid side of the scene's lattice, or a ConfigError when it exceeds
    :data:`MAX_GRID_SIDE`."""
    n = Lattice.of(n_side, phi, elements_per_diameter, lattice).grid_side
    if n > MAX_GRID_SIDE:
        m = padded_size(n)
        raise ConfigError("elements_per_diameter", elements_per_diameter,
                          f"a resolution giving at most {MAX_GRID_SIDE} elements per side "
                          f"(this one gives {n} for n_side={n_side}, lattice {lattice}; its "
                          f"padded FFT grid of {m} x {m} alone would need about "
                          f"{BYTES_PER_FFT_ELEMENT * m * m / 2**30:.0f} GiB)")
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


#: bytes per active element of the lattice level: the unit-moment shapes (3 float64), the
#: centred coordinates (2), the attached set (uint8), and during an update the moment columns
#: and their block solves (6)
LATTICE_BYTES_PER_ELEMENT = 89
#: float64 values per pillar of the lattice level: D_g and F_gg (18) and the inner CG's vectors
#: (8 x 3)
LATTICE_VALUES_PER_PILLAR = 42
#: nodes of the padded lattice per pillar, at most: twice the lattice each way, the lattice at
#: most ``lattice.MAX_LATTICE_FILL`` (4) nodes per pillar
LATTICE_NODES_PER_PILLAR = 16
#: bytes per padded lattice node, an upper bound: while the kernels are built their real-space
#: values (72), the offsets (16), the nine complex spectra and their normalised copy (2 x 72);
#: kept, the FFT buffers (2 x 3 real on the lattice rows, about half the padded ones, and 3
#: half-complex) and the spectra's six real rows (24). tracemalloc: a build peak of 243-249
#: bytes per node, 75-79 kept (2026-11-28, benchmarks/NOTES.md "The lattice couplings' spectra
#: by their symmetry")
LATTICE_BYTES_PER_NODE = 320


def lattice_bytes(n_pillars: int, n_active: int,
                  nodes_per_pillar: int = LATTICE_NODES_PER_PILLAR) -> int:
    """Peak bytes of the lattice coarse level (:mod:`fibril_hpc.solve.lattice`) on
    ``n_pillars`` pillars with ``n_active`` active elements and ``nodes_per_pillar`` nodes of the
    padded lattice per pillar (at most :data:`LATTICE_NODES_PER_PILLAR`; 4 on a square lattice);
    its block-Jacobi level not included."""
    return ((8 * LATTICE_VALUES_PER_PILLAR + nodes_per_pillar * LATTICE_BYTES_PER_NODE)
            * n_pillars + LATTICE_BYTES_PER_ELEMENT * n_active)


#: bytes per active element of one preload snapshot a loading path keeps until its branch is
#: pulled off: p, u, p1, u1 as float64 and the attached set (33, ``records.Snapshot``), and what
#: the unloading branches allocate beside them (a path through 7 preloads measured 370-400 bytes
#: per active element above one through a single preload, 48 x 7 + 67 = 403)
SNAPSHOT_BYTES_PER_ELEMENT = 48
#: bytes per active element of the driver's state saved while a snapshot is taken ahead (eight
#: float64 vectors and three uint8 sets; ``snapshots.SnapshotMixin._STATE``)
SAVED_STATE_BYTES_PER_ELEMENT = 67


def snapshot_bytes(n_preloads: int, n_active: int) -> int:
    """Peak bytes of the preload snapshots of one loading path through ``n_preloads`` preloads
    on ``n_active`` active elements: all are kept until the unloading branches run, plus the
    saved state while the last is taken."""
    if n_preloads < 1:
        return 0
    return (SNAPSHOT_BYTES_PER_ELEMENT * n_preloads + SAVED_STATE_BYTES_PER_ELEMENT) * n_active


#: bytes per grid element (n x n, not the padded m x m) of the pillar states a result keeps:
#: each preload's state at the preload and at the pull-off holds an n x n float32 pressure map
#: and a uint8 contact map (``api._pillar_state``)
STATE_MAP_BYTES = 5
#: bytes per grid element of the one float32 map being built at a time
STATE_MAP_BUILD_BYTES = 4


def state_map_bytes(n_preloads: int, grid_side: int) -> int:
    """Peak bytes of the pillar states' n x n maps that a path through ``n_preloads`` preloads
    keeps in its result (two states per preload), with the one being built. They grow the
    peak past a run's first events: a 316 x 316 `fast` run peaked 27 % above its first three
    events (benchmarks/NOTES.md, "316 × 316 at `fast`, reference and moments side by side")."""
    if n_preloads < 1:
        return 0
    return (2 * STATE_MAP_BYTES * n_preloads + STATE_MAP_BUILD_BYTES) * grid_side**2


def uses_coarse_level(scene) -> bool:
    """Whether ``scene``'s solver builds a coarse level (``auto``, ``two_level``, ``moments``
    or ``lattice``; counted whatever the footprints: an upper bound)."""
    return scene.solver.preconditioner in ("auto", "two_level", "moments", "lattice")


def coarse_level_bytes(scene, fft_size: int, n_active: int) -> int:
    """Peak bytes of the coarse level ``scene``'s solver builds on an FFT of side ``fft_size``
    (0 when it builds none): the one ``auto`` takes (:func:`~fibril_hpc.solve.factory.auto_kind`;
    a scene's pillars always lie on a lattice), or the one asked for. A square lattice pads to
    4 nodes per pillar; other lattices are bounded by :data:`LATTICE_NODES_PER_PILLAR`."""
    if not uses_coarse_level(scene):
        return 0
    ng = scene.n_side**2
    kind = scene.solver.preconditioner
    if kind == "auto":
        kind = auto_kind(ng, fft_size)
    if kind == "lattice":
        return lattice_bytes(ng, n_active, 4 if scene.lattice == "square"
                             else LATTICE_NODES_PER_PILLAR)
    if kind == "moments":
        return moment_bytes(ng, n_active)
    return coarse_bytes(ng, n_active)


def memory_estimate(scene, preloads: int | None = None) -> tuple[int, int, int]:
    """(estimated peak bytes of one ``simulate`` call, grid side, FFT side) of ``scene`` on a
    loading path through ``preloads`` preloads (default: the scene's own)."""
    lat = Lattice.of(scene.n_side, scene.phi, scene.elements_per_diameter, scene.lattice)
    n = lat.grid_side
    m = padded_size(n)
    active = scene.n_side**2 * lat.elements_per_pillar
    if preloads is None:
        preloads = len(scene.preloads)
    need = BYTES_PER_FFT_ELEMENT * m * m + BASE_BYTES
    need += coarse_level_bytes(scene, m, active) + snapshot_bytes(preloads, active)
    need += state_map_bytes(preloads, n)
    return need, n, m


def _read_int(path: str) -> int | None:
    try:
        with open(path) as fh:
            text = fh.read().strip()
        return int(text)
    except (OSError, ValueError):
        return None


def _own_cgroups(proc: str = "/proc") -> list:
    """(version, path) of the memory cgroups of this process, from ``/proc/self/cgroup``:
    ``(2, "/a/b")`` for the unified hierarchy (``0::/a/b``), ``(1, "/a/b")`` for a v1 memory
    controller line (``N:memory:/a/b``)."""
    out = []
    try:
        with open(os.path.join(proc, "self", "cgroup")) as fh:
            lines = fh.read().splitlines()
    except OSError:
        return out
    for line in lines:
        parts = line.split(":", 2)
        if len(parts) != 3:
            continue
        _, ctrls, path = parts
        if ctrls == "":
            out.append((2, path))
        elif "memory" in ctrls.split(","):
            out.append((1, path))
    return out


def cgroup_memory(proc: str = "/proc", sys_fs: str = "/sys/fs/cgroup") -> int | None:
    """Bytes this process may still use under its own memory cgroup(s) and their parents (v2
    ``memory.max`` - ``memory.current``, v1 ``memory.limit_in_bytes`` - ``memory.usage_in_bytes``),
    None when no limit is set."""
    best = None
    for version, path in _own_cgroups(proc):
        base = sys_fs if version == 2 else os.path.join(sys_fs, "memory")
        files = (("memory.max", "memory.current") if version == 2 else
                 ("memory.limit_in_bytes", "memory.usage_in_bytes"))
        if version == 2 and not os.path.exists(os.path.join(base, "cgroup.controllers")):
            base = os.path.join(sys_fs, "unified")      # a hybrid host
        rel = path.strip("/")
        while True:                                      # the cgroup, then each parent
            folder = os.path.join(base, rel) if rel else base
            limit = _read_int(os.path.join(folder, files[0]))
            if limit is not None and 0 < limit < (1 << 60):
                used = _read_int(os.path.join(folder, files[1])) or 0
                left = max(0, limit - used)
                best = left if best is None else min(best, left)
            if not rel:
                break
            rel = os.path.dirname(rel)
    return best


def address_space_left(proc: str = "/proc") -> int | None:
    """Bytes of address space left under ``RLIMIT_AS`` (``ulimit -v``), None when unlimited."""
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft == resource.RLIM_INFINITY or soft < 0:
        return None
    size = 0
    try:
        with open(os.path.join(proc, "self", "status")) as fh:
            for line in fh:
                if line.startswith("VmSize:"):
                    size = int(line.split()[1]) * 1024
                    break
    except (OSError, ValueError):
        pass
    return max(0, soft - size)


def available_memory(proc: str = "/proc", sys_fs: str = "/sys/fs/cgroup") -> int | None:
    """Bytes of memory available to this process now (None when unknown): the least of
    ``MemAvailable`` (``/proc/meminfo``), what its own cgroup v1/v2 (and each parent) leaves,
    read through ``/proc/self/cgroup``, and the address space left under ``RLIMIT_AS``."""
    avail = None
    try:
        with open(os.path.join(proc, "meminfo")) as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    avail = int(line.split()[1]) * 1024
                    break
    except (OSError, ValueError):
        pass
    for left in (cgroup_memory(proc, sys_fs), address_space_left(proc)):
        if left is not None:
            avail = left if avail is None else min(avail, left)
    return avail


def check_memory(scene, *, available: int | None = None, field: str = "scene",
                 preloads: int | None = None) -> int:
    """The estimate (on a path through ``preloads`` preloads; default: the scene's own), or a
    ConfigError when it exceeds the memory available."""
    need, n, m = memory_estimate(scene, preloads)
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


__all__ = ["check_grid", "check_memory", "check_job_count", "memory_estimate", "snapshot_bytes",
           "coarse_bytes", "moment_bytes", "available_memory", "MAX_GRID_SIDE", "MAX_JOBS",
           "state_map_bytes"]
