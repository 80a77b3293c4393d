"""A griffe extension for the API reference (mkdocs.yml): the docstrings' Sphinx roles
(``:class:`~fibril_hpc.inputs.scene.Scene```, ``:meth:`to_dataframe```, ...) become links.

mkdocstrings does not read Sphinx roles: the API page showed them raw. Each role becomes an
*optional* cross-reference of mkdocs-autorefs: a link where its target is documented on the
site, the name in code type elsewhere (a private helper, the standard library), never a raw
marker and never a warning of ``mkdocs build --strict``. The target is resolved as Sphinx does:
a full path as given, ``~`` shows its last part, a leading dot searches the enclosing packages,
a bare name the object's own scope and imports (griffe's ``resolve``).
"""

from __future__ import annotations

import html
import re

import griffe

#: a Sphinx role of the Python domain: :role:`target` (title forms "text <target>" included)
ROLE = re.compile(r":(?:py:)?(?:class|func|meth|data|attr|mod|exc|obj|const):`([^`]+)`")


def convert(text: str, resolve) -> str:
    """``text`` with every Sphinx role replaced by an optional autoref: ``resolve(name)`` gives
    the full path of a target as written (without ``~``), or None when it knows none."""

    def one(m) -> str:
        target = m.group(1).strip()
        title = None
        if target.endswith(">") and "<" in target:            # :role:`title <target>`
            title, target = (s.strip() for s in target[:-1].split("<", 1))
        short = target.startswith("~")
        name = target.lstrip("~")
        path = resolve(name) or name.lstrip(".")
        if title is None:
            title = path.rsplit(".", 1)[-1] if short else name.lstrip(".")
        return (f'<autoref identifier="{html.escape(path, quote=True)}" optional>'
                f"<code>{html.escape(title)}</code></autoref>")

    return ROLE.sub(one, text)


def _resolver(obj, collection):
    def exists(path: str) -> bool:
        try:
            collection.get_member(path)
        except (KeyError, ValueError, AttributeError, griffe.AliasResolutionError):
            return False
        return True

    def resolve(name: str) -> str | None:
        if name.startswith("."):                 # relative: the enclosing packages, inner first
            parts = obj.module.path.split(".")
            for i in range(len(parts), 0, -1):
                path = ".".join(parts[:i]) + name
                if exists(path):
                    return path
            return None
        head, _, rest = name.partition(".")
        if exists(name) and "." in name:
            return name
        try:
            base = obj.resolve(head)
        except (griffe.NameResolutionError, ValueError, KeyError, AttributeError):
            return None
        return base + ("." + rest if rest else "")

    return resolve


class SphinxRoles(griffe.Extension):
    """Rewrite the Sphinx roles of every docstring of a loaded package (see the module)."""

    def on_package(self, *, pkg, loader, **kwargs) -> None:  # noqa: ARG002
        """Convert the docstrings of ``pkg`` and of everything in it."""
        stack = [pkg]
        while stack:
            obj = stack.pop()
            if obj.is_alias:
                continue
            if obj.docstring is not None and ":" in obj.docstring.value:
                obj.docstring.value = convert(obj.docstring.value,
                                              _resolver(obj, loader.modules_collection))
            stack.extend(m for m in obj.members.values() if not m.is_alias)
