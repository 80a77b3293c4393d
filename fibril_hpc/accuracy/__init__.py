"""The accuracy study (``fibril-accuracy``): what accuracy costs in time.

Measures the error of F~_A and F~_P (or, for force-controlled preloads, of the indentation d~_max
that reaches F~_P) and the wall/CPU time as each accuracy knob varies, one at a time and combined
(the presets), and writes ``accuracy.csv`` (one row per run), ``accuracy.md`` (the tables) and
``pareto.png`` (error against time, with the Pareto front).

Cases (every run single-threaded, ``fft_threads = 1``, so that times are comparable):

``pillar``
    one rigid, flat-ended pillar (``n_side = 1``), displacement preload d~ = 1. Exact: Kendall,
    F~_A = phi_d^(1/4), and the punch stiffness, F~_P = phi_d^(1/2) d~ (phi_d: discrete filling
    ratio of the very run, so the exact values follow the discrete footprint).
``brush6``
    a rough, spring-backed 6 x 6 brush (k~ = 0.01, sigma~ = 0.5, seed 0, displacement preload
    d~ = 18, about F~_P = 4, so that F~_P is an output). No closed form: the reference is the
    case's finest run (tight knobs if such a run exists at that resolution, else the default
    knobs, whose own knob error the study measures separately and finds far below the resolution
    error); its uncertainty is the largest deviation of the runs at >= 2/3 of its resolution.
``brush18``
    the default 18 x 18 scene (k~ = 0.01, sigma~ = 0.5, seed 0, F~_P = 4: force-controlled, so
    the preload-side error is that of d~_max). Reference as for ``brush6`` (finest affordable:
    its uncertainty is large, see the tables).

Each preset is also run with the opt-in local confirmation (``solver.confirm: local``,
docs/model.md §6; rows of kind ``local``, labelled ``<preset> + confirm: local``): a point of its
own on the error-against-time plot, measured as the presets are, and compared with its preset's
run (change of F~_A, ratios of CPU time and FFT pairs) in ``accuracy.md``; and with the opt-in far
field by pillar moments (``solver.far_field: multipole``; kind ``multipole``), which is not
certified: its point shows what its error costs and saves.

Every row also carries the "knob error": the difference from the tight-knob run at the same
resolution, which separates the solver-knob error from the discretisation error.

``--quick`` checks the machinery in well under a minute (tiny grids, CI); the full mode is for a
person (the 18 x 18 case takes hours at its finest grids: select cases with ``--cases``). Rows
already in ``accuracy.csv`` of the output folder are reused with ``--resume``, so a long study can
be run case by case. A bad argument is one line on stderr, exit status 2, nothing written.

Modules: :mod:`.study` (cases, runs, references and errors), :mod:`.report` (tables and plot);
the command is :mod:`fibril_hpc.cli.accuracy`. Only the public API is used (``Scene``,
``simulate``, the presets, :mod:`fibril_hpc.analytic`).
"""


from .report import markdown, pareto, plot, preset_summary
from .study import (CASES, FIELDS, KNOB_VALUES, TIGHT, add_errors, plan, read_rows, reference,
                    run_case, write_csv)

__all__ = ["CASES", "FIELDS", "KNOB_VALUES", "TIGHT", "add_errors", "plan", "read_rows",
           "reference", "run_case", "write_csv", "markdown", "pareto", "plot", "preset_summary"]
