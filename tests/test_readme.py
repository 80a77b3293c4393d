"""README's promises to a new user: a snippet names the extra it needs, the test commands are
the ones CI and the markers run."""

import os
import re
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _read(rel: str) -> str:
    with open(os.path.join(ROOT, rel), encoding="utf-8") as fh:
        return fh.read()


def _extras() -> dict:
    return tomllib.loads(_read("pyproject.toml"))["project"]["optional-dependencies"]


def _names(reqs) -> set:
    return {re.split(r"[<>=\[ ;]", r, maxsplit=1)[0].lower() for r in reqs}


def test_every_python_snippet_of_readme_names_the_extra_it_needs():
    """A snippet calling to_dataframe / to_xarray says which extra to install, and that extra
    holds pandas and xarray (with their engines): the quick start installs neither."""
    blocks = re.findall(r"```python\n(.*?)```", _read("README.md"), re.S)
    needing = [b for b in blocks if "to_dataframe" in b or "to_xarray" in b]
    assert needing
    extras = _extras()
    quick = re.search(r"pip install \"\.\[(\w+)\]\" && mpirun", _read("README.md")).group(1)
    assert not {"pandas", "xarray"} & _names(extras[quick])
    for b in needing:
        named = re.search(r'pip install "\.\[([\w,]+)\]"', b)
        assert named, b
        have = set().union(*(_names(extras[e]) for e in named.group(1).split(",")))
        assert {"pandas", "pyarrow", "xarray", "h5netcdf"} <= have, (named.group(1), have)


def test_readme_names_the_full_test_run_ci_runs_and_the_quick_one():
    readme = _read("README.md")
    ci = _read(".ci/run")
    assert re.search(r"^pytest -q$", ci, re.M)                   # CI: the full run
    assert "`pytest -q`" in readme and '`pytest -q -m "not slow"`' in readme
    # the quick start's test command is CI's, exactly
    quick = re.search(r'pip install "\.\[test[\w,]*\]" && (pytest[^#\n]*?)\s*#', readme).group(1)
    assert quick == "pytest -q"
    opts = tomllib.loads(_read("pyproject.toml"))["tool"]["pytest"]["ini_options"]
    assert "-m" not in opts["addopts"].split()        # a bare `pytest -q` deselects nothing
    assert any(m.startswith("slow:") for m in opts["markers"])
