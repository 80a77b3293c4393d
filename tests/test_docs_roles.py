"""The API reference shows no raw Sphinx role: docs/hooks/sphinx_roles.py (configured in
mkdocs.yml) turns them into cross-references mkdocs-autorefs resolves or shows as code."""

import importlib.util
import os
import re

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
HOOK = os.path.join(ROOT, "docs", "hooks", "sphinx_roles.py")


def _hook():
    pytest.importorskip("griffe")
    spec = importlib.util.spec_from_file_location("sphinx_roles", HOOK)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_roles_become_optional_autorefs():
    hook = _hook()
    known = {"Scene": "fibril_hpc.inputs.scene.Scene", ".data.CampaignData":
             "fibril_hpc.campaign.analysis.data.CampaignData"}
    out = hook.convert("a :class:`~fibril_hpc.io.results.Curve`, :class:`Scene`, "
                       ":attr:`~.data.CampaignData.n_side_swept`, :meth:`.data.CampaignData`, "
                       ":func:`the reader <fibril_hpc.io.store.read_result_file>` and "
                       ":func:`difflib.get_close_matches`.", lambda name: known.get(name))
    assert ":class:" not in out and ":func:" not in out and ":attr:" not in out
    assert ('<autoref identifier="fibril_hpc.io.results.Curve" optional><code>Curve</code>'
            '</autoref>') in out
    assert '<autoref identifier="fibril_hpc.inputs.scene.Scene" optional><code>Scene</code>' in out
    assert ('identifier=".data.CampaignData.n_side_swept"' not in out
            and '<code>n_side_swept</code>' in out)            # unknown: the name, as code
    assert ('identifier="fibril_hpc.campaign.analysis.data.CampaignData" optional>'
            '<code>data.CampaignData</code>') in out
    assert ('identifier="fibril_hpc.io.store.read_result_file" optional><code>the reader</code>'
            in out)
    assert 'identifier="difflib.get_close_matches" optional' in out


def test_no_docstring_of_the_api_page_keeps_a_role():
    """Every object docs/api.md documents, loaded as mkdocs.yml loads it: no role left, and
    the targets resolve to full paths."""
    hook = _hook()
    import griffe

    with open(os.path.join(ROOT, "mkdocs.yml"), encoding="utf-8") as fh:
        assert "docs/hooks/sphinx_roles.py:SphinxRoles" in fh.read()
    with open(os.path.join(ROOT, "docs", "api.md"), encoding="utf-8") as fh:
        targets = re.findall(r"^::: (\S+)", fh.read(), re.M)
    pkg = griffe.load("fibril_hpc", search_paths=[ROOT], extensions=griffe.load_extensions(
        hook.SphinxRoles()), docstring_parser="numpy")
    seen = 0
    for t in targets:
        stack = [pkg.get_member(t.removeprefix("fibril_hpc."))]
        while stack:
            obj = stack.pop()
            if obj.docstring is not None:
                seen += 1
                assert not hook.ROLE.search(obj.docstring.value), (obj.path, obj.docstring.value)
            stack.extend(m for m in obj.members.values() if not m.is_alias)
    assert seen > 20
    doc = pkg.get_member("campaign.analysis.data.CampaignData.to_dataframe").docstring.value
    assert 'identifier="fibril_hpc.campaign.analysis.si.SI_COLUMNS"' in doc
    assert 'identifier="fibril_hpc.campaign.analysis.data.CampaignData.n_side_swept"' in doc
