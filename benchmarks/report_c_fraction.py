"""The adhesion coefficient c as the chord over a fraction f of the rise: how well the paper's
law c = max(alpha/sigma~ - beta, 0) follows it for f = 0.3, 0.5 (the report's), 0.7.

    python benchmarks/report_c_fraction.py CAMPAIGN.h5 [N_BOOT]

Prints, per f and k~: c per sigma~, the median seed half-width of c, alpha, beta, sigma~_c and
chi^2/dof of the fit (benchmarks/NOTES.md, "Report on real campaigns").
"""

import sys

import numpy as np

from fibril_hpc import load_campaign
from fibril_hpc.campaign.analysis.report_data import points_by_group
from fibril_hpc.campaign.laws.study import study


def main(path, n_boot=100):
    pts = points_by_group(load_campaign(path, curves=False).jobs)
    for half in (0.3, 0.5, 0.7):
        print(f"fraction {half}:")
        for k, st in study(pts, n_boot=n_boot, half=half).items():
            cs = " ".join(f"{g.reading.c:.3g}" for g in st.groups)
            rel = np.nanmedian([(g.c_ci[1] - g.c_ci[0]) / 2 / g.reading.c for g in st.groups
                                if g.reading.c > 0])
            a = st.ab
            print(f"  k={k:g}: c = {cs}; median seed half-width {100 * rel:.0f} %; alpha "
                  f"{a.alpha:.3g} beta {a.beta:.3g} sigma_c {a.sigma_c:.3g} chi2/dof "
                  f"{a.chi2_red:.3g}")


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 100)
