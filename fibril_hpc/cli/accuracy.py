"""``fibril-accuracy``: the accuracy study on the command line (see :mod:`fibril_hpc.accuracy`)."""

from __future__ import annotations

import os
import sys

from .._version import __version__
from ..accuracy import CASES, add_errors, markdown, plot, read_rows, run_case
from ..accuracy.study import run_one
from ..errors import EXIT_FAILED, EXIT_OK, EXIT_USAGE, ConfigError
from ..io.files import check_output_folder, write_text_atomically
from ..io.results import software_versions
from .common import Parser, add_version, error, interruptible, memory_guard, pipe_safe

PROG = "fibril-accuracy"
#: the files written into --out
OUTPUTS = ("accuracy.csv", "accuracy.md", "pareto.png")


@pipe_safe
@interruptible(PROG, "the finished rows are in --out's accuracy.csv; rerun with --resume")
@memory_guard(PROG)
def main(argv=None) -> int:
    """``fibril-accuracy``; returns the exit status."""
    p = Parser(prog=PROG, description="What accuracy costs in time: errors of F~_A and F~_P "
               "against wall and CPU time as each accuracy knob varies.")
    p.add_argument("--out", default="accuracy-study", metavar="DIR",
                   help="output folder (accuracy.csv, accuracy.md, pareto.png)")
    p.add_argument("--quick", action="store_true", help="machinery check on tiny grids (CI)")
    p.add_argument("--cases", default=None,
                   help="comma-separated subset of " + ", ".join(CASES) +
                        " (default: pillar,brush6 in quick mode, all otherwise)")
    p.add_argument("--resume", action="store_true",
                   help="reuse the rows already in DIR/accuracy.csv (run cases one at a time)")
    p.add_argument("--code", default=f"fibril_hpc {__version__}", metavar="LABEL",
                   help="label of the code that runs, recorded per row (timings depend on it; "
                        "default: the package version; e.g. a git commit)")
    add_version(p)
    p.add_argument("--report-only", action="store_true",
                   help="rewrite the table and plot from DIR/accuracy.csv without running")
    p.add_argument("--force", action="store_true",
                   help="replace the accuracy.csv, accuracy.md and pareto.png already in DIR "
                        "(without --resume or --report-only they are refused)")
    args = p.parse_args(argv)
    try:
        cases = (args.cases.split(",") if args.cases else
                 (["pillar", "brush6"] if args.quick else list(CASES)))
        for c in cases:
            if c not in CASES:
                raise ConfigError("--cases", c, "a comma-separated subset of " + ", ".join(CASES))
            if args.quick and CASES[c]["quick"] is None:
                raise ConfigError("--cases", c, "in --quick mode: pillar, brush6")
        check_output_folder(args.out, "--out")
        csv_path = os.path.join(args.out, "accuracy.csv")
        if args.report_only and not os.path.exists(csv_path):
            raise ConfigError("--report-only", csv_path, "an existing accuracy.csv in --out")
        from ..campaign.storage.guard import check_output

        for name in OUTPUTS:          # --resume / --report-only rewrite what they read
            check_output(os.path.join(args.out, name), "--out",
                         force=args.force or args.resume or args.report_only)
    except ConfigError as exc:
        return error(PROG, exc, EXIT_USAGE)
    os.makedirs(args.out, exist_ok=True)
    rows = read_rows(csv_path) if (args.resume or args.report_only) else []
    if not args.report_only:
        run_one(dict(n_side=2, k_tilde=0.01, sigma_tilde=0.5, d_tilde=1.0), 4, {})   # warm-up:
        # numba's cached kernels and FFTW load here, not inside the first timed run
        for c in cases:
            run_case(c, args.quick, rows, csv_path, code=args.code)
    refs = add_errors(rows)
    write_text_atomically(os.path.join(args.out, "accuracy.md"),
                          markdown(rows, refs, args.quick, software_versions()),
                          "writing the accuracy table")
    plot(rows, os.path.join(args.out, "pareto.png"))
    print(f"fibril-accuracy: {len(rows)} runs; wrote {args.out}/accuracy.csv, accuracy.md, "
          "pareto.png")
    return EXIT_OK if all(r["status"] == "ok" for r in rows) else EXIT_FAILED


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
