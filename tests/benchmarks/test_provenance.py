"""Provenance (benchmarks/provenance.py): the code version with its git commit, and without git."""

import shutil
import subprocess

import pytest

from sarcover.benchmarks.provenance import PACKAGE_DIR, code_version, git_commit, version_with_commit

needs_git = pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")


def _git(folder, *args):
    subprocess.run(["git", "-C", str(folder), *args], check=True, capture_output=True,
                   env={"GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t", "GIT_COMMITTER_NAME": "t",
                        "GIT_COMMITTER_EMAIL": "t@t", "PATH": "/usr/bin:/bin", "HOME": str(folder)})


def test_version_label_names_the_commit_and_a_dirty_tree():
    """The commit becomes a PEP 440 local label; ``.dirty`` marks uncommitted changes; no commit, no label."""
    assert version_with_commit("0.1.0", ("1a2b3c4d", False)) == "0.1.0+g1a2b3c4d"
    assert version_with_commit("0.1.0", ("1a2b3c4d", True)) == "0.1.0+g1a2b3c4d.dirty"
    assert version_with_commit("0.1.0", None) == "0.1.0"


@needs_git
def test_git_commit_of_a_checkout_clean_then_dirty(tmp_path):
    """A checkout's short commit is HEAD's; a changed tracked file makes it dirty, an untracked file does not."""
    _git(tmp_path, "init", "-q")
    (tmp_path / "a.py").write_text("x = 1\n")
    _git(tmp_path, "add", "a.py")
    _git(tmp_path, "commit", "-q", "-m", "one")
    head = subprocess.run(["git", "-C", str(tmp_path), "rev-parse", "HEAD"], capture_output=True, text=True).stdout
    sha, dirty = git_commit(tmp_path)
    assert head.startswith(sha) and len(sha) == 8 and not dirty
    (tmp_path / "results.jsonl").write_text("{}\n")
    assert git_commit(tmp_path) == (sha, False)
    (tmp_path / "a.py").write_text("x = 2\n")
    assert git_commit(tmp_path) == (sha, True)


@needs_git
def test_no_commit_outside_a_checkout_or_inside_another_repository(tmp_path):
    """Outside any repository, or in a subfolder of another repository, there is no commit of one's own."""
    assert git_commit(tmp_path) is None
    _git(tmp_path, "init", "-q")
    (tmp_path / "pkg").mkdir()
    assert git_commit(tmp_path / "pkg") is None


def test_code_version_of_this_package_has_its_commit_when_run_from_a_checkout():
    """This package's code version is its installed version, labelled with its commit when in a checkout."""
    from importlib.metadata import version

    fresh = code_version.__wrapped__()  # the cached value is this process's first; the tree may have changed since
    assert fresh == version_with_commit(version("sarcover"), git_commit(PACKAGE_DIR))
    assert fresh.startswith(version("sarcover")) and code_version().startswith(version("sarcover"))
