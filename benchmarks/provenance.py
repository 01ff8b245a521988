"""Where a row comes from: the code version (with its git commit) and the machine's packages.

:func:`code_version` is the installed version, plus the commit when the package runs from a git
checkout (``0.1.0+g1a2b3c4``, ``.dirty`` when tracked files differ from that commit), so two
rows made by different code never carry the same version. Outside a checkout (an installed
wheel, git missing) it is the plain version. :func:`environment` is the provenance part of every
row and of every ``runs.jsonl`` record.
"""

from __future__ import annotations

import os
import platform
import subprocess
from functools import cache
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parents[1]  # the repository root is the sarcover package
PACKAGES = ("numpy", "scipy", "pandas", "scikit-learn", "pyomo", "highspy", "ortools", "pyvrp", "numba", "dask",
            "distributed")


def _version(package: str) -> str | None:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(package)
    except PackageNotFoundError:
        return None


def _git(args: list[str], where: Path) -> str | None:
    """``git -C where ARGS``'s output, or None when git is missing, fails or takes over 5 s."""
    try:
        out = subprocess.run(["git", "-C", str(where), *args], capture_output=True, text=True, timeout=5,
                             env={**os.environ, "GIT_OPTIONAL_LOCKS": "0"})  # a read must not take index.lock
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() if out.returncode == 0 else None


def git_commit(where: Path = PACKAGE_DIR) -> tuple[str, bool] | None:
    """(short commit, dirty) of the git checkout whose top folder is ``where``, else None (a
    package installed inside some other repository's tree is not that repository's code)."""
    top = _git(["rev-parse", "--show-toplevel"], where)
    if top is None or Path(top).resolve() != where.resolve():
        return None
    sha = _git(["rev-parse", "--short=8", "HEAD"], where)
    if not sha:
        return None
    status = _git(["status", "--porcelain", "--untracked-files=no"], where)
    return sha, bool(status)


def version_with_commit(base: str, commit: tuple[str, bool] | None) -> str:
    """``base`` with the commit as a PEP 440 local version label: ``0.1.0+g1a2b3c4d[.dirty]``."""
    if commit is None:
        return base
    sha, dirty = commit
    return f"{base}+g{sha}" + (".dirty" if dirty else "")


@cache
def code_version() -> str:
    """This process's sarcover version with its commit (computed once per process)."""
    return version_with_commit(_version("sarcover") or "unknown", git_commit())


@cache
def environment() -> dict:
    """Machine and package versions of this process (computed once per process); ``versions``
    holds ``sarcover``'s :func:`code_version`."""
    versions = {"python": platform.python_version(), "sarcover": code_version()}
    versions.update({pkg: _version(pkg) for pkg in PACKAGES})
    return {"host": platform.node(), "platform": platform.platform(terse=True), "cpu_count": os.cpu_count(),
            "versions": versions}
