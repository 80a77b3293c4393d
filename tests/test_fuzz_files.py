"""Fuzz test of every reader of HDF5 files (issue 18): real small campaign and result files,
mutated (flipped bits, truncation, zeroed blocks, and crafted links, attributes, dtypes, shapes
and external storage), are read by the library readers and by ``fibril-campaign`` (in process).

Asserted for every mutated file: no exception other than a one-line StoreError/ConfigError,
error lines within the cap, and nothing foreign counted: every record a reader returns is one
of the original records with its original numbers; and no hang: a read that makes libhdf5
loop (some zeroed blocks of the global heap do) must be stopped by the reader itself
(fibril_hpc.io.isolate) and reported in one line. The mutations are drawn from fixed seeds
(reproducible: the failing case names its seed and mutation): 1 000 mutated files, about two
minutes on two shared cores (benchmarks/NOTES.md).
"""

from __future__ import annotations

import os
import random
import shutil
import signal

import h5py
import numpy as np
import pytest

from campaign_helpers import write_grid
from fibril_hpc import load_campaign
from fibril_hpc.campaign import load_spec
from fibril_hpc.campaign.run.runner import run_serial
from fibril_hpc.campaign.storage import journal as J
from fibril_hpc.campaign.storage.writer import CampaignWriter
from fibril_hpc.errors import ConfigError, StoreError

#: byte-level mutations (flips, truncations, zeroed blocks) of the campaign file
N_BYTES = 640
#: structured mutations (links, attributes, datasets) of the campaign file
N_CRAFTED = 32
#: mutations of a single-run result file (read_result_file)
N_RESULT = 328
#: seconds any one reader may take on one file (a hang fails the test)
HANG_S = 20


@pytest.fixture(autouse=True)
def quick_stall(monkeypatch):
    """A reader that loops inside libhdf5 (some zeroed blocks do that) is stopped after 1 s of
    reading nothing instead of the product's 15 s (fibril_hpc.io.isolate)."""
    from fibril_hpc.io import isolate

    monkeypatch.setattr(isolate, "STALL_S", 1.0)


@pytest.fixture(scope="module")
def seed_files(tmp_path_factory):
    """A finished 4-job campaign and a fibril-run result file."""
    from fibril_hpc.api import simulate
    from fibril_hpc.inputs.scene import Scene
    from fibril_hpc.io.store import write_result_file

    d = tmp_path_factory.mktemp("fuzz_seed")
    grid = write_grid(d, k_tilde=1, sigma_tilde=0.3)
    spec = load_spec(grid)
    assert run_serial(spec, progress=False) == 0
    original = {j["key"]: j for j in load_campaign(spec.output).jobs}
    result = str(d / "run.h5")
    write_result_file(result, simulate(Scene(n_side=2, elements_per_diameter=5, F_P=(1.0,))))
    return spec, original, result


class Hang(Exception):
    pass


def _alarm(signum, frame):
    raise Hang()


def guarded(what, fn, *args, **kw):
    """``fn(*args)``: a StoreError/ConfigError (one line, capped) is fine; anything else, or
    more than HANG_S seconds, fails with ``what`` (the seed and the mutation)."""
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(HANG_S)
    try:
        return fn(*args, **kw)
    except (StoreError, ConfigError) as exc:
        text = str(exc)
        assert "\n" not in text.strip(), (what, text)
        return exc
    except Hang:
        pytest.fail(f"{what}: {getattr(fn, '__name__', fn)} hung for {HANG_S} s")
    except Exception as exc:  # noqa: BLE001 - what the test is for
        pytest.fail(f"{what}: {getattr(fn, '__name__', fn)} raised "
                    f"{type(exc).__name__}: {str(exc)[:300]}")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def same_record(a: dict, b: dict) -> bool:
    if a["record_id"] != b["record_id"] or repr(a["F_A"]) != repr(b["F_A"]) or \
            repr(a["F_P"]) != repr(b["F_P"]) or a["status"] != b["status"]:
        return False
    for br in ("loading", "unloading"):
        ca, cb = a.get(br), b.get(br)
        if (ca is None) != (cb is None):
            return False
        if ca is not None and not all(np.array_equal(ca[k], cb[k], equal_nan=True) for k in cb):
            return False
    return True


def nothing_foreign(what, data, original):
    """Every record returned is an original record with its original numbers."""
    if isinstance(data, Exception):
        return
    for j in data.jobs:
        assert j["key"] in original, (what, "foreign key counted", j["key"])
        assert same_record(j, original[j["key"]]), (what, "changed numbers published", j["key"])


# ------------------------------------------------------------------ mutations
def byte_mutation(rng: random.Random, data: bytes) -> tuple[bytes, str]:
    b = bytearray(data)
    kind = rng.choice(("flip", "flips", "truncate", "zero"))
    if kind == "flip":
        at = rng.randrange(len(b))
        b[at] ^= 1 << rng.randrange(8)
        return bytes(b), f"flip byte {at}"
    if kind == "flips":
        ats = [rng.randrange(len(b)) for _ in range(rng.randint(2, 16))]
        for at in ats:
            b[at] ^= 1 << rng.randrange(8)
        return bytes(b), f"flips {ats[:4]}..."
    if kind == "truncate":
        at = rng.randrange(len(b))
        return bytes(b[:at]), f"truncate at {at}"
    at = rng.randrange(len(b)) // 512 * 512
    b[at:at + 512] = bytes(len(b[at:at + 512]))
    return bytes(b), f"zero 512 at {at}"


def _members(fh):
    out = []
    fh.visititems(lambda name, obj: out.append((name, obj)))
    return out


HOSTILE_VALUES = (lambda rng: "x" * rng.randint(0, 5000), lambda rng: np.zeros(rng.randint(2, 9)),
                  lambda rng: rng.random(), lambda rng: rng.randint(-10**12, 10**12),
                  lambda rng: float("nan"), lambda rng: b"\xff\xfe",
                  lambda rng: "[" * 50_000, lambda rng: np.bool_(True))


def crafted_mutation(rng: random.Random, path: str, other: str) -> str:
    """Change the HDF5 file at ``path`` in place in one crafted way; returns what was done."""
    with h5py.File(path, "r+") as fh:
        members = _members(fh)
        groups = [(n, o) for n, o in members if isinstance(o, h5py.Group)] + [("", fh)]
        datasets = [(n, o) for n, o in members if isinstance(o, h5py.Dataset)]
        kind = rng.choice(("attr", "del_attr", "del_checksum", "soft_loop", "external_link",
                           "dataset_dtype", "dataset_shape", "huge", "external_storage",
                           "delete", "empty_group", "rename_key"))
        if kind in ("attr", "del_attr"):
            name, obj = rng.choice(groups)
            attrs = list(obj.attrs)
            if not attrs:
                return "nothing"
            a = rng.choice(attrs)
            if kind == "del_attr":
                del obj.attrs[a]
                return f"del {name}@{a}"
            obj.attrs[a] = rng.choice(HOSTILE_VALUES)(rng)
            return f"set {name}@{a}"
        if kind == "del_checksum":
            jobs = fh["jobs"]
            k = rng.choice(sorted(jobs))
            jobs[k].attrs.pop("checksum", None)
            jobs[k].attrs["F_A"] = 9.99
            return f"strip checksum of {k} and change F_A"
        if kind == "soft_loop":
            name, obj = rng.choice(groups)
            obj[f"loop{rng.randrange(99)}"] = h5py.SoftLink("/" + name if name else "/")
            return f"soft loop in /{name}"
        if kind == "external_link":
            jobs = fh["jobs"]
            k = rng.choice(sorted(jobs))
            target = rng.choice(("fedcba9876543210", k))
            if target in jobs:
                del jobs[target]
            jobs[target] = h5py.ExternalLink(other, f"/jobs/{k}")
            return f"external link /jobs/{target}"
        if not datasets:
            return "nothing"
        name, ds = rng.choice(datasets)
        parent, leaf = ds.parent, name.rsplit("/", 1)[-1]
        if kind == "dataset_dtype":
            n = ds.shape[0] if ds.shape else 1
            del parent[leaf]
            parent.create_dataset(leaf, data=np.array(["ab"] * n, dtype="S2"))
        elif kind == "dataset_shape":
            data = ds[()]
            del parent[leaf]
            parent.create_dataset(leaf, data=np.atleast_1d(data)[:, None])
        elif kind == "huge":
            del parent[leaf]
            parent.create_dataset(leaf, shape=(3_000_000_000,), dtype="f8", chunks=(4096,))
        elif kind == "external_storage":
            n = max(1, ds.shape[0] if ds.shape else 1)
            del parent[leaf]
            parent.create_dataset(leaf, shape=(n,), dtype="f8",
                                  external=[("/etc/passwd", 0, 8 * n)])
        elif kind == "delete":
            del parent[leaf]
        elif kind == "empty_group":
            fh["jobs"].create_group(f"{rng.getrandbits(64):016x}")
        elif kind == "rename_key":
            jobs = fh["jobs"]
            k = rng.choice(sorted(jobs))
            jobs.move(k, f"{rng.getrandbits(64):016x}")
        return f"{kind} {name}"


# ------------------------------------------------------------------ readers
def read_everything(what, path, original, tmp, capsys):
    from fibril_hpc.campaign.analysis.status import file_status
    from fibril_hpc.campaign.storage.merge import merge_records
    from fibril_hpc.campaign.storage.verify import salvage_file, verify_file
    from fibril_hpc.cli.campaign import main

    nothing_foreign(what, guarded(what, load_campaign, path), original)
    guarded(what, load_campaign, path, include_unchecked=True)
    guarded(what, verify_file, path)
    guarded(what, file_status, path)
    guarded(what, merge_records, [path])
    out = os.path.join(tmp, "salvaged.h5")
    if not isinstance(guarded(what, salvage_file, path, out), Exception):
        nothing_foreign(what + " (salvaged)", guarded(what, load_campaign, out), original)
        os.unlink(out)
    for args in (["status", path], ["verify", path],
                 ["export", path, "--csv", os.path.join(tmp, "x.csv")],
                 ["merge", path, "-o", os.path.join(tmp, "m.h5")]):
        capsys.readouterr()
        code = guarded(what, main, args)
        err = capsys.readouterr().err
        assert code in (0, 1, 2), (what, args, code)
        assert "Traceback" not in err and all(len(ln) <= 500 for ln in err.splitlines()), \
            (what, args, err[:500])
    merged = os.path.join(tmp, "m.h5")
    if os.path.exists(merged):
        nothing_foreign(what + " (merged)", guarded(what, load_campaign, merged), original)
        os.unlink(merged)


@pytest.mark.slow
def test_fuzz_campaign_files_bytes(seed_files, tmp_path, capsys, caplog):
    spec, original, _ = seed_files
    with open(spec.output, "rb") as fh:
        data = fh.read()
    rng = random.Random(18_001)
    path = str(tmp_path / "f.h5")
    for i in range(N_BYTES):
        mutated, what = byte_mutation(rng, data)
        what = f"bytes #{i} ({what})"
        with open(path, "wb") as fh:
            fh.write(mutated)
        for side in (J.journal_path(path),):
            if os.path.exists(side):
                os.unlink(side)
        # the cheap readers on every file, the whole CLI on every 40th
        nothing_foreign(what, guarded(what, load_campaign, path), original)
        if i % 40 == 0:
            read_everything(what, path, original, str(tmp_path), capsys)
        caplog.clear()


@pytest.mark.slow
def test_fuzz_campaign_files_crafted(seed_files, tmp_path, capsys, caplog):
    spec, original, _ = seed_files
    other = str(tmp_path / "other.h5")
    shutil.copy(spec.output, other)
    rng = random.Random(18_002)
    path = str(tmp_path / "f.h5")
    for i in range(N_CRAFTED):
        shutil.copy(spec.output, path)
        done = [crafted_mutation(rng, path, other) for _ in range(rng.randint(1, 3))]
        what = f"crafted #{i} ({'; '.join(done)})"
        read_everything(what, path, original, str(tmp_path), capsys)
        if i % 8 == 0:           # the writer (resume) publishes nothing foreign either
            guarded(what, _open_and_close_writer, spec, path)
            nothing_foreign(what + " (after the writer)", guarded(what, load_campaign, path),
                            original)
        for side in (J.journal_path(path), path + ".lock"):
            if os.path.exists(side):
                os.unlink(side)
        caplog.clear()


def _open_and_close_writer(spec, path):
    spec = load_spec(spec.source, path)
    CampaignWriter(spec).close()


@pytest.mark.slow
def test_fuzz_result_files(seed_files, tmp_path):
    from fibril_hpc.io.store import read_result_file

    _, _, result = seed_files
    with open(result, "rb") as fh:
        data = fh.read()
    other = str(tmp_path / "other.h5")
    shutil.copy(result, other)
    rng = random.Random(18_003)
    path = str(tmp_path / "r.h5")
    ok = 0
    for i in range(N_RESULT):
        if i % 2:
            mutated, what = byte_mutation(rng, data)
            with open(path, "wb") as fh:
                fh.write(mutated)
        else:
            shutil.copy(result, path)
            with h5py.File(path, "r+") as fh:        # crafted: give it a /jobs to aim at
                fh.require_group("jobs").create_group("0000000000000000")
            what = crafted_mutation(rng, path, other)
        got = guarded(f"result #{i} ({what})", read_result_file, path)
        ok += not isinstance(got, Exception)
    assert ok < N_RESULT          # the mutations did reach the reader
