"""The shipped example grids and Slurm scripts, as package data (the repository's
``campaigns/`` and ``slurm/`` folders link here), so that an installed fibril-hpc can hand them
out: ``fibril-campaign example NAME``. Depends on nothing else of the package."""

from __future__ import annotations

from importlib import resources

#: folders of package data, in the order they are listed
FOLDERS = ("grids", "slurm")


def _files():
    root = resources.files(__name__)
    out = {}
    for folder in FOLDERS:
        for entry in sorted(root.joinpath(folder).iterdir(), key=lambda e: e.name):
            if entry.is_file() and entry.name.endswith((".yaml", ".sbatch", ".sh")):
                out[entry.name] = entry
    return out


def names() -> list[str]:
    """Every example's file name (``demo.yaml``, ``campaign.sbatch``, ...)."""
    return list(_files())


def resolve(name: str) -> str | None:
    """The example called ``name`` (with or without its extension), or None."""
    files = _files()
    if name in files:
        return name
    stems = [n for n in files if n.rsplit(".", 1)[0] == name]
    return stems[0] if len(stems) == 1 else None


def text(name: str) -> str:
    """The text of the example ``name`` (a name from :func:`names`)."""
    return _files()[name].read_text(encoding="utf-8")


def summary(name: str) -> str:
    """The example's first comment line, without the ``#``."""
    for line in text(name).splitlines():
        line = line.strip()
        if line.startswith("#") and not line.startswith("#!") and not line.startswith("#SBATCH"):
            return line.lstrip("#").strip()
    return ""


def is_script(name: str) -> bool:
    """Whether the example is a shell script (written executable)."""
    return name.endswith((".sbatch", ".sh"))


__all__ = ["names", "resolve", "text", "summary", "is_script"]
