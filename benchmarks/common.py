"""What every benchmark records about the code it ran: the commit and modified files."""

from __future__ import annotations

import os
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def git_state(root: str = ROOT) -> dict:
    """Commit and the modified tracked files of the checkout at ``root`` ({} without git)."""
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True,
                              text=True, timeout=30).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                               cwd=root, capture_output=True, text=True, timeout=30).stdout
        return {"commit": head, "modified": [ln[3:] for ln in dirty.splitlines()]}
    except (OSError, subprocess.SubprocessError):
        return {}
