"""The sarcover CLI end to end: generate, solve, methods, plots, and one-line errors (exit 2)."""

import json
import subprocess
import sys

import pytest

from sarcover.benchmarks.cli import main
from conftest import TOP_DIR


def run(*args):
    """Run the real console entry point in a subprocess (no traceback may leak)."""
    return subprocess.run([sys.executable, "-m", "sarcover.benchmarks.cli", *args], capture_output=True, text=True)


def test_generate_solve_json_and_plot(tmp_path):
    """generate → solve --json → a verified greedy plan; --plot writes a PNG."""
    inst = tmp_path / "i.json"
    assert main(["generate", "-M", "6", "-K", "3", "-N", "2", "--seed", "4", "-o", str(inst)]) == 0
    out = run("solve", str(inst), "--json", "--plot", str(tmp_path / "p.png"))
    assert out.returncode == 0, out.stderr
    rec = json.loads(out.stdout)
    for key in ("method", "status", "objective", "bound", "coverage", "routes", "energy", "runtime_s", "valid"):
        assert key in rec
    assert rec["method"] == "greedy" and rec["status"] == "feasible" and rec["valid"] is True
    assert rec["bound"] is None
    assert rec["objective"] == sum(len(r) for r in rec["routes"])
    assert (tmp_path / "p.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("method", ["milp", "cpsat", "bp"])
def test_solve_json_stdout_is_one_object_for_exact_methods(tmp_path, method):
    """`solve --json` prints exactly one JSON object: no solver banner (HiGHS prints one from C++
    when a highspy model is built) may reach stdout."""
    inst = tmp_path / "i.json"
    assert main(["generate", "-M", "4", "-K", "2", "-N", "2", "--seed", "1", "-o", str(inst)]) == 0
    out = run("solve", str(inst), "--method", method, "--json", "--time-limit", "20")
    assert out.returncode == 0, out.stderr
    rec = json.loads(out.stdout)
    assert rec["method"] == method and rec["status"] == "optimal" and rec["valid"] is True
    # bp's numba code is compiled (or loaded) first, and the user is told so on stderr
    assert ("compiling numba code" in out.stderr) == (method == "bp")


def test_solve_json_carries_bp_info_with_an_audited_proof():
    """`solve --json` on a bp run that proves by a root listing and audits it: its info (numpy
    counters included) comes out as one JSON object, the audit in it."""
    out = run("solve", "p2.2.k", "--method", "bp", "--json", "--time-limit", "60", "--param", "enum_share=0.5",
              "--param", "enum_gap=1.0", "--param", "audit_listings=true")
    assert out.returncode == 0, out.stderr
    rec = json.loads(out.stdout)
    assert rec["status"] == "optimal" and rec["info"]["enum_status"] == "infeasible"
    assert rec["info"]["audit"]["audit_passed"] is True


def test_solve_top_file_summary():
    """A TOP benchmark file solves; the readable summary names method and objective."""
    out = run("solve", str(TOP_DIR / "p2.2.k.txt"))
    assert out.returncode == 0, out.stderr
    assert "greedy (heuristic)" in out.stdout and "objective" in out.stdout


def test_methods_lists_greedy_as_heuristic(capsys):
    """`sarcover methods` lists greedy, marked heuristic."""
    assert main(["methods"]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("greedy"))
    assert "heuristic" in line


def test_infeasible_instance_is_a_status(tmp_path):
    """An E_max too small for any view is status infeasible with the target named, exit code 3
    (no plan); the JSON object still comes out."""
    inst = tmp_path / "i.json"
    main(["generate", "-M", "4", "-K", "2", "-N", "1", "--e-max", "50", "-o", str(inst)])
    out = run("solve", str(inst), "--json")
    rec = json.loads(out.stdout)
    assert out.returncode == 3 and rec["status"] == "infeasible" and "target 0" in rec["reason"]


@pytest.mark.parametrize(
    "args, needle",
    [
        (["solve", "missing.json"], "no such file"),
        (["solve", "{inst}", "--method", "nope"], "unknown method 'nope'"),
        (["solve", "{inst}", "--time-limit", "-3"], "--time-limit"),
        (["solve", "{inst}", "--plot", "/no/such/dir/p.png"], "does not exist"),
        (["solve", "{notjson}"], "not valid JSON"),
        (["solve", "{badfield}"], "e_max"),
        (["generate", "-M", "0", "-K", "2", "-N", "1", "-o", "x.json"], "--targets"),
        (["generate", "-M", "3", "-K", "0", "-N", "1", "-o", "x.json"], "--views"),
        (["generate", "-M", "3", "-K", "2", "-N", "1", "--e-max", "nan", "-o", "x.json"], "--e-max"),
        (["frobnicate"], "invalid choice"),
    ],
)
def test_bad_input_one_line_exit_2(tmp_path, args, needle):
    """Bad input: exactly one stderr line naming the problem, exit 2, no traceback."""
    inst = tmp_path / "i.json"
    main(["generate", "-M", "3", "-K", "2", "-N", "1", "-o", str(inst)])
    (tmp_path / "n.json").write_text("{oops")
    (tmp_path / "b.json").write_text(inst.read_text().replace('"e_max"', '"e_maxx"'))
    args = [a.format(inst=inst, notjson=tmp_path / "n.json", badfield=tmp_path / "b.json") for a in args]
    out = subprocess.run([sys.executable, "-m", "sarcover.benchmarks.cli", *args], capture_output=True, text=True,
                         cwd=tmp_path)
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0] and "Traceback" not in out.stderr


def test_a_name_too_long_for_the_file_system_is_bad_input(capsys):
    """A file name longer than the file system allows (found by the argument-list property
    test) is bad input like a missing file: one line naming it, exit 2, no traceback, whichever
    command gets it (an instance, a suite, a results or output directory)."""
    name = "1" + "0" * 400
    assert main(["solve", name]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cannot read" in err[0] and name in err[0]
    for argv in (["bench", name, "-o", "unused"], ["report", name], ["bench", "quick", "-o", name]):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and name in err[0] and "too long" in err[0], argv


def test_sigterm_as_interrupt_raises_within_the_block_and_restores_after():
    """The shared SIGTERM handling of the CLI and cluster_timing: KeyboardInterrupt inside the
    block, the previous handler back after it."""
    import os
    import signal
    import time

    from sarcover.benchmarks.cli import sigterm_as_interrupt

    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(KeyboardInterrupt):
        with sigterm_as_interrupt():
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(1.0)  # the handler runs here, in the main thread
    assert signal.getsignal(signal.SIGTERM) is before
