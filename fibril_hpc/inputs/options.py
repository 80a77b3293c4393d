"""The solver options of a scene: a frozen, validated dataclass of numerical knobs.

Each option has a documented default, a range checked at construction (a one-line
:class:`~fibril_hpc.errors.ConfigError` naming ``solver.<option>``) and a kind
(:data:`OPTION_KINDS`) saying whether it defines the result, how it is computed, or only what it
spends. :class:`~fibril_hpc.inputs.scene.Scene` holds one.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from ..errors import ConfigError
from .presets import DEFAULT_PRESET, preset_values
from .ranges import Choice, Int, Real, check_fields

#: Detachment criteria (``SolverOptions.criterion``; :mod:`fibril_hpc.path.criterion`).
CRITERIA = ("mesh", "footprint")

#: The direction solve's tolerance over ``cg_tol`` when ``solver.direction_tol`` is not given.
DIRECTION_SLACK = 100.0

#: What a solver option decides (``SolverOptions`` field metadata ``kind``): ``accuracy``
#: options define the result (presets set them), ``backend`` ones how it is computed (equal to
#: rounding; in job keys too, as keys promise bitwise identity), ``resource`` ones only cap or
#: spend resources (left out of job keys).
OPTION_KINDS = ("accuracy", "backend", "resource")


def _opt(default, kind: str, rng, operator_arg: str = "", extra: bool = False):
    meta = {"kind": kind, "range": rng}
    if operator_arg:
        meta["operator_arg"] = operator_arg     # the HalfSpace argument this option sets
    if extra:
        meta["extra"] = True    # stored in the scene text only off its default (Scene.to_dict)
    return dataclasses.field(default=default, metadata=meta)



@dataclass(frozen=True)
class SolverOptions:
    """Numerical knobs; every one has a documented default.

    Attributes
    ----------
    cg_tol : float
        Relative tolerance of the constrained CG, measured against the half-space part of the
        operator: ``||r|| <= cg_tol * ||K p||`` (docs/model.md §4: stays accurate for soft springs).
        Range (0, 1e-2]. Default 1e-8.
    cg_maxiter : int
        Iteration cap of one CG solve; exceeding it is a :class:`NoConvergenceError`. Default 5000.
    relax_tol : float
        CG tolerance of the intermediate passes of a detachment/attachment cascade at fixed d; a
        set that is stable at it is confirmed at ``cg_tol`` before the cascade ends. Setting it
        equal to ``cg_tol`` (or below) solves every pass fully. Range (0, 1e-2]. Default 1e-5.
    event_merge : float
        While unloading, contact-set events whose plate displacement lies within this distance (in
        units of d_c) after the first one are handled as one batch: the path moves to the last of
        them before the set is relaxed. The force just before the first event is always recorded
        exactly. Range [0, 1]. Default 1e-4.
    load_event_merge : float
        The same while loading, where it hardly changes F_A (the set at the preload is what
        matters) but saves many solves. Range [0, 1]. Default 1e-2.
    load_merge_spread : float
        While loading, a batch also spans at most this fraction of the scene's own length
        spread s (the standard deviation of the realised pillar setbacks, tip offsets included):
        the batch is ``min(load_event_merge d_c, load_merge_spread s)``. A smooth brush (sigma~
        = 0.01: every length within about 0.06 d_c) then still touches pillar by pillar and the
        rise of F~_A with preload is resolved; with ``load_event_merge`` in d_c alone the
        ``fast`` preset put all 324 pillars of an 18 x 18 brush in one batch. Only brushes with
        sigma~ < ``load_event_merge / load_merge_spread`` feel it (below 0.1 for ``default``,
        below 1 for ``fast``). At 0.1, F~_A at the smallest preloads of a sigma~ = 0.01 brush is
        within 3 % of the unbatched path; 0.01 brings it within 0.1 % at 1.5x the FFT pairs
        (benchmarks/NOTES.md, "Loading batches and the rise"). Range [0, 100]. Default 0.1.
    max_events : int
        Cap on contact-set events along one curve (a runaway guard). Default 1_000_000.
    max_wall_s : float or None
        Wall-time cap of one simulation in seconds (``None``: none); exceeding it fails the
        simulation with that reason (campaigns use it to turn a runaway job into a failed record).
    preconditioner : str
        ``"auto"`` (default: for pillars of one footprint the coarse level of
        ``solve.factory.auto_kind``: ``"lattice"`` from 400 pillars on and where the FFT is
        dear enough (``solve.factory.prefers_moments``), else ``"two_level"``; else
        ``"diagonal"``), ``"block"`` (exact per-pillar block Jacobi), ``"diagonal"``
        (c0 I + alpha B B^T), ``"two_level"`` (block Jacobi plus a coarse level of one force per
        pillar in contact, :mod:`fibril_hpc.solve.coarse`; at most 1296 pillars), ``"moments"``
        (three coarse unknowns per pillar, force and tilts, a dense inverse;
        :mod:`fibril_hpc.solve.moments`; at most 1296 pillars) or ``"lattice"`` (the same three
        unknowns, coupled by FFT on the pillar lattice and solved iteratively;
        :mod:`fibril_hpc.solve.lattice`; no cap).
        All reach the same answer; ``"auto"`` keeps its name in scene texts and job keys.
    detach_policy : str
        ``"all"`` (reference: every supercritical element detaches in one pass) or ``"worst"``
        (only the most supercritical element of each pillar per pass). Default ``"all"``.
    fft_backend : str
        ``"pyfftw"`` (default) or ``"numpy"`` (reference/comparison).
    fft_threads : int or None
        Threads of the FFT pair; ``None`` (default) means one. With T > 1 each pair's rows and
        column blocks are shared between T threads (bitwise the same product): worth it for a
        lone big scene (36 x 36: 1.14-1.28x in wall time on two threads, measured in two
        sessions) and not for small ones (the default 18 x 18 scene: 1.02x), where less of the
        time is in the FFT (``benchmarks/NOTES.md``). MPI campaigns run one single-threaded job
        per rank. BLAS and the numba kernels run on one thread.
    fft_planner : str
        FFTW planning effort: ``"estimate"`` (default, instant), ``"measure"`` or ``"patient"``.
    cascade : str
        How a detachment/attachment cascade at fixed d is solved (does not define the result:
        both reach the same fixed point, tested): ``"local"`` (default: the pillars whose set
        changed are solved directly with the rest of the grid held, then one global solve
        confirms) or ``"global"`` (the reference: a global solve per pass).
    criterion : str
        Detachment criterion (docs/model.md §5): ``"mesh"`` (default: an element of side h
        detaches at sigma_c = sqrt(E* dgamma/(kappa h))) or ``"footprint"`` (sigma_c scaled by
        one factor per pillar footprint and mesh, chosen so that one isolated rigid flat pillar of
        that footprint pulls off at exactly Kendall's force; :mod:`fibril_hpc.path.criterion`). Flat
        tips only. Stored in the scene text, and part of job keys, only off its default.
    direction_tol : float or None
        Relative CG tolerance of the direction solve p1 = A^-1 1_S on each new contact set
        (docs/model.md §6). ``None`` (default): ``DIRECTION_SLACK`` (100) times ``cg_tol``, at
        most 1e-2. The state at every event is solved at ``cg_tol``; the direction only carries it
        to the next event, so its error moves the located events and the forces recorded just
        before them by about ``direction_tol`` times the step, never the relaxed states
        (measured on the default scene: F~_A within 2e-9 of the ``cg_tol`` direction, 1.17-1.19x
        fewer FFT pairs; benchmarks/NOTES.md §21). Range (0, 1e-2]. Stored in the scene text, and
        part of job keys, only off its default.
    confirm : str
        How the state after a contact event is confirmed (needs ``cascade: local``):
        ``"global"`` (default, the reference: a global solve at ``cg_tol`` ends every
        relaxation) or ``"local"`` (a local fixed point is accepted without that solve when a
        certified bound on its force error, from its exact residual and the direction solved on
        its set, is at most ``confirm_tol``; else the global solve runs:
        :mod:`fibril_hpc.solve.certify`). Results record the relaxations confirmed each way and
        the largest bound. Stored in the scene text, and part of job keys, only off its default.
    confirm_tol : float
        Largest certified force error (in F~ units, F_c) of a state that ``confirm: local``
        accepts without a global solve. Range (0, 1e-2]. Default 5e-5. Stored in the scene text,
        and part of job keys, only off its default.
    far_field : str
        How CG applies the half-space in the states' solves between two exact products:
        ``"exact"`` (default, the reference: every iteration is one FFT pair of the element
        grid) or ``"multipole"`` (each pillar's own block exact, every other pillar through its
        force and two tilts, by FFT on the pillar lattice; while unloading the state's field is
        made exact after every ``far_refresh`` held solves, and sooner where the force bound of
        a state that ends a relaxation exceeds ``confirm_tol``; while loading after every 2 at
        most; the direction's solves stay exact:
        :mod:`fibril_hpc.solve.farfield`, :mod:`fibril_hpc.path.confirm`). 0.48-0.59 x the
        reference's CPU (medians over the 18 x 18 and 36 x 36 corner scenes, two runs side by
        side on a 16-core machine). Under displacement control the force of every state that
        ends a relaxation is certified within ``confirm_tol`` of the exact state on its contact
        set; which element lets go when is not, so F~_A is not certified and is measured
        against the reference (docs/model.md §6). Needs pillars of
        one footprint on a lattice and ``confirm: global``; the local cascade is not used with
        it. Stored in the scene text, and part of job keys, only off its default.
    far_refresh : int
        Solves of the state held with the moments between two exact products while unloading
        under ``far_field: multipole`` (one exact product per ``far_refresh`` + 1 state solves
        at most: the states' force bound asks for one sooner where it exceeds ``confirm_tol``;
        while loading after 2 at most; CG
        iterates with the moments right after a refresh too, so no value reproduces the
        reference; a larger value left to the bound alone moves the contact events and F~_A,
        benchmarks/NOTES.md). Range [1, 1e6]. Default 4. Stored in the scene text, and part of
        job keys, only off its default.
    """

    cg_tol: float = _opt(1e-8, "accuracy", Real(0, 1e-2, lo_open=True))
    cg_maxiter: int = _opt(5000, "accuracy", Int(1, 10**7))
    relax_tol: float = _opt(1e-5, "accuracy", Real(0, 1e-2, lo_open=True))
    event_merge: float = _opt(1e-4, "accuracy", Real(0, 1))
    load_event_merge: float = _opt(1e-2, "accuracy", Real(0, 1))
    load_merge_spread: float = _opt(0.1, "accuracy", Real(0, 100), extra=True)
    max_events: int = _opt(1_000_000, "resource", Int(1, 10**9))
    max_wall_s: float | None = _opt(None, "resource", Real(0, lo_open=True, none="null"))
    preconditioner: str = _opt("auto", "accuracy",
                               Choice(("auto", "block", "diagonal", "two_level", "moments", "lattice")))
    detach_policy: str = _opt("all", "accuracy", Choice(("all", "worst")))
    fft_backend: str = _opt("pyfftw", "backend", Choice(("pyfftw", "numpy")), "backend")
    fft_threads: int | None = _opt(None, "resource", Int(1, 1024, none="null (one thread)"),
                                   "threads")
    fft_planner: str = _opt("estimate", "backend", Choice(("estimate", "measure", "patient")),
                            "planner")
    cascade: str = _opt("local", "backend", Choice(("local", "global")))
    criterion: str = _opt("mesh", "accuracy", Choice(CRITERIA), extra=True)
    direction_tol: float | None = _opt(None, "accuracy",
                                       Real(0, 1e-2, lo_open=True,
                                            none=f"null ({DIRECTION_SLACK:g} x cg_tol)"),
                                       extra=True)
    confirm: str = _opt("global", "accuracy", Choice(("global", "local")), extra=True)
    confirm_tol: float = _opt(5e-5, "accuracy", Real(0, 1e-2, lo_open=True), extra=True)
    far_field: str = _opt("exact", "accuracy", Choice(("exact", "multipole")), extra=True)
    far_refresh: int = _opt(4, "accuracy", Int(1, 10**6), extra=True)

    def __post_init__(self):
        check_fields(self, "solver.")
        if self.confirm == "local" and self.cascade != "local":
            raise ConfigError("solver.confirm", self.confirm, "'global' (or 'local' together "
                              "with solver.cascade: local)")
        if self.far_field == "multipole" and self.confirm == "local":
            raise ConfigError("solver.far_field", self.far_field, "'exact' (solver.confirm: "
                              "local certifies with the exact field, which 'multipole' has "
                              "only right after a refresh)")

    @classmethod
    def from_preset(cls, name: str = DEFAULT_PRESET, **overrides) -> SolverOptions:
        """The options of an accuracy preset (:mod:`fibril_hpc.inputs.presets`) with explicit overrides."""
        return cls(**{**preset_values(name)["solver"], **overrides})

    @classmethod
    def of_kind(cls, kind: str) -> tuple:
        """Names of the options of one kind (see :data:`OPTION_KINDS`), in field order."""
        return tuple(f.name for f in dataclasses.fields(cls) if f.metadata["kind"] == kind)

    def operator_settings(self) -> dict:
        """The keyword arguments of :class:`~fibril_hpc.elastic.halfspace.HalfSpace` these options set
        (``fft_threads`` resolved): what an operator, and so an operator cache, depends on."""
        return {f.metadata["operator_arg"]: (self.threads if f.name == "fft_threads"
                                             else getattr(self, f.name))
                for f in dataclasses.fields(self) if "operator_arg" in f.metadata}

    @property
    def direction_tolerance(self) -> float:
        """Resolved tolerance of the direction solve: ``direction_tol``, else
        ``DIRECTION_SLACK * cg_tol`` capped at 1e-2 (see the attribute's docs)."""
        if self.direction_tol is not None:
            return self.direction_tol
        return min(1e-2, DIRECTION_SLACK * self.cg_tol)

    @property
    def threads(self) -> int:
        """Resolved FFT thread count: ``fft_threads``, else 1 (see the attribute's docs)."""
        return 1 if self.fft_threads is None else self.fft_threads

    def replace(self, **changes) -> SolverOptions:
        """A copy with options changed (validated again)."""
        return dataclasses.replace(self, **changes)


SOLVER_FIELDS = tuple(f.name for f in dataclasses.fields(SolverOptions))
