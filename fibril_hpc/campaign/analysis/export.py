"""Export of a campaign, one row per job with the columns of
:data:`fibril_hpc.campaign.storage.record.COLUMNS` (then ``n_side`` when the brush size is an
axis of the file: :attr:`~.data.CampaignData.n_side_swept`, then one per swept lab field:
:attr:`~.data.CampaignData.lab_sweeps`, then, for a grid in physical units, the SI columns
of :data:`~.si.SI_COLUMNS`, as :meth:`~.data.CampaignData.to_dataframe` has them): CSV
(no extra dependency) and Parquet (pandas + pyarrow: the ``report`` extra); and the whole
campaign, curves included, as netCDF (xarray + h5netcdf: the ``netcdf`` extra)."""

from __future__ import annotations

import csv
import io
import os

from ...io.files import write_bytes_atomically, write_text_atomically
from ..storage.record import COLUMNS
from .data import load_campaign
from .dataset import netcdf_available, to_xarray
from .si import has_units, si_columns


def _csv_value(v):
    if isinstance(v, float):
        return repr(v)
    return "" if v is None else v


def export_csv(path: str, out: str, include_unchecked: bool = False,
               exclusive: str | None = None) -> int:
    """Write the jobs of the campaign file ``path`` to ``out`` (atomically: temporary file +
    rename; a full disk is a one-line :class:`~fibril_hpc.errors.DiskFull`); returns the rows.
    Records without a checksum are left out unless ``include_unchecked``. With ``exclusive``
    (the option naming ``out``) ``out`` must be new, checked atomically as it is written (see
    :func:`fibril_hpc.io.files.write_bytes_atomically`)."""
    c = load_campaign(path, curves=False, include_unchecked=include_unchecked)
    cols = COLUMNS + (("n_side",) if c.n_side_swept else ())
    extra = {n: c.lab_column(n) for n in c.lab_sweeps}
    if has_units(c.meta):              # N, m, N/m beside the normalised columns, as Parquet has
        extra.update({n: v.tolist() for n, v in si_columns(c.jobs).items()})
    buf = io.StringIO(newline="")
    w = csv.writer(buf)
    w.writerow(cols + tuple(extra))
    for i, j in enumerate(c.jobs):
        w.writerow([_csv_value(j.get(col)) for col in cols]
                   + [_csv_value(v[i]) for v in extra.values()])
    write_text_atomically(out, buf.getvalue(), "writing the CSV export", exclusive)
    return len(c.jobs)


def parquet_available() -> bool:
    """Whether pandas and pyarrow can be imported (Parquet export)."""
    try:
        import pandas  # noqa: F401
        import pyarrow  # noqa: F401
    except ImportError:
        return False
    return True


def export_parquet(path: str, out: str, include_unchecked: bool = False,
                   exclusive: str | None = None) -> int:
    """Write the jobs of ``path`` to the Parquet file ``out`` (atomically, typed columns);
    returns the rows. Needs pandas and pyarrow. Unchecked records and ``exclusive`` as in
    :func:`export_csv`."""
    df = load_campaign(path, curves=False, include_unchecked=include_unchecked).to_dataframe()
    buf = io.BytesIO()
    df.to_parquet(buf, engine="pyarrow", index=False)
    write_bytes_atomically(out, buf.getvalue(), "writing the Parquet export",
                           "." + os.path.basename(out) + ".part-", exclusive)
    return len(df)


def export_netcdf(path: str, out: str, curves: bool = True,
                  include_unchecked: bool = False, exclusive: str | None = None) -> int:
    """Write the campaign file ``path`` as the netCDF-4 file ``out`` through h5netcdf
    (atomically): the Dataset of :func:`~fibril_hpc.campaign.analysis.dataset.to_xarray`, which
    ``xarray.open_dataset(out)`` gives back equal; returns the jobs written. ``exclusive`` as in
    :func:`export_csv`."""
    data = load_campaign(path, curves=curves, include_unchecked=include_unchecked)
    blob = to_xarray(data, curves=curves).to_netcdf(engine="h5netcdf")
    write_bytes_atomically(out, bytes(blob), "writing the netCDF export",
                           "." + os.path.basename(out) + ".part-", exclusive)
    return len(data.jobs)


__all__ = ["export_csv", "export_parquet", "export_netcdf", "parquet_available",
           "netcdf_available"]
