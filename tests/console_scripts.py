"""The console scripts as ``pip install`` writes them, from pyproject's ``[project.scripts]``
(so that tests run this tree's entry points, not those of an older installed copy)."""

import os
import stat
import sys
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

#: pip's console-script template (pip/_vendor/distlib/scripts.py)
TEMPLATE = """#!{python}
import sys
from {module} import {func}
if __name__ == '__main__':
    sys.argv[0] = sys.argv[0].removesuffix('.exe')
    sys.exit({func}())
"""


def entry_points() -> dict:
    """``{script name: "module:function"}`` of pyproject.toml."""
    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as fh:
        return tomllib.load(fh)["project"]["scripts"]


def write_scripts(folder) -> str:
    """Write every console script into ``folder`` (created) and return it; the scripts import
    fibril_hpc from this tree (PYTHONPATH) with this interpreter."""
    os.makedirs(folder, exist_ok=True)
    for name, target in entry_points().items():
        module, func = target.split(":")
        path = os.path.join(folder, name)
        with open(path, "w") as fh:
            fh.write(TEMPLATE.format(python=sys.executable, module=module, func=func))
        os.chmod(path, os.stat(path).st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
    return str(folder)


def script_env(folder) -> dict:
    """The environment in which ``folder``'s scripts (and nothing older) run this tree."""
    env = dict(os.environ)
    env["PATH"] = str(folder) + os.pathsep + env.get("PATH", "")
    env["PYTHONPATH"] = ROOT + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    env.setdefault("NUMBA_CACHE_DIR", os.path.join(ROOT, ".numba_cache"))
    return env
