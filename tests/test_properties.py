"""Property-based tests (hypothesis) of the instance readers and the CLI's solve and generate.

Any JSON value, any TOP-file text and any argument list must give an instance (or exit code 0) or
a documented error: an InstanceError of one line, or exit code 2/3/4 with at most one line on
stderr. Never a traceback, never another exception, never a numpy warning. Examples are bounded
(small lists, few examples, greedy as the only runnable method) so that the default run stays fast.
"""

import atexit
import contextlib
import io
import json
import math
import os
import shutil
import tempfile
import warnings
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, event, example, given, settings
from hypothesis import strategies as st

from sarcover.benchmarks.cli import EXIT_BAD_INPUT, EXIT_METHOD_ERROR, EXIT_NO_PLAN, EXIT_OK, main
from sarcover.formulations.errors import InstanceError
from sarcover.formulations.generate import generate
from sarcover.formulations.instance import to_top
from sarcover.formulations.io import load_instance, read_top, sar_from_dict, sar_to_dict

FAST = settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
SOLVE_CODES = {EXIT_OK, EXIT_BAD_INPUT, EXIT_NO_PLAN, EXIT_METHOD_ERROR}
WORK = Path(tempfile.mkdtemp(prefix="sarcover-props-"))  # files the examples read and write
atexit.register(shutil.rmtree, WORK, ignore_errors=True)

# numbers that break things: huge, tiny, negative, non-finite, integers beyond float
numbers = st.one_of(
    st.integers(min_value=-(10**30), max_value=10**30),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, 1, -1, 2, 3, 1e15, 1e16, 1e300, -1e300, 5e-324, 10**400, 10**7, 10**9, 1.5]),
)
json_scalars = st.one_of(st.none(), st.booleans(), numbers, st.text(max_size=8))
json_values = st.recursive(json_scalars, lambda inner: st.one_of(
    st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=6), inner, max_size=4)), max_leaves=12)

VALID = sar_to_dict(generate(3, 2, 2, seed=1))
FIELDS = list(VALID) + ["extra", "e_maxx"]


@st.composite
def instance_dicts(draw):
    """A valid instance with a few fields replaced by any JSON value, removed, or added."""
    data = json.loads(json.dumps(VALID))
    for _ in range(draw(st.integers(1, 3))):
        key = draw(st.sampled_from(FIELDS))
        action = draw(st.sampled_from(["replace", "replace", "delete", "coordinate"]))
        if action == "delete":
            data.pop(key, None)
        elif action == "coordinate":
            data["targets"] = [list(t) for t in VALID["targets"]]
            data["targets"][draw(st.integers(0, 2))][draw(st.integers(0, 1))] = draw(numbers)
        else:
            data[key] = draw(json_values)
    return data


@contextlib.contextmanager
def strict():
    """Warnings (numpy's overflow and invalid value) become errors: no input may cause one."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        yield


def check_accepted(top) -> None:
    """What a reader accepts is usable: finite coordinates and, for small instances, finite energies."""
    assert np.all(np.isfinite(top.coords)) and math.isfinite(top.budget)
    if top.n_nodes <= 300:
        assert np.all(np.isfinite(top.cost_matrix()))


def one_line(exc: Exception) -> None:
    assert str(exc) and "\n" not in str(exc), repr(exc)


@FAST
@given(st.one_of(json_values, instance_dicts()))
@example({**VALID, "targets": [[999999999999388.0, 1900.0]] + VALID["targets"][1:]})  # views beyond the limit
@example({**VALID, "views": 10**7})
@example({**VALID, "uavs": 10**9})
@example({**VALID, "targets": [[1e300, 1e300]]})
@example({**VALID, "e_maxx": 1})
def test_any_json_value_is_an_instance_or_one_instance_error(value):
    """Any JSON value is read as an instance or refused with one InstanceError line, nothing else."""
    with strict():
        try:
            sar = sar_from_dict(value, source="x.json")
        except InstanceError as exc:
            one_line(exc)
            event("refused")
        else:
            check_accepted(to_top(sar))
            event("accepted")


TOKENS = st.one_of(numbers.map(str), st.sampled_from(["n", "m", "tmax", "nan", "inf", "-inf", "1e999", "x", ""]),
                   st.text(alphabet="0123456789.-e+ nmtax", max_size=6))


NUMERIC = st.one_of(st.integers(-5, 30).map(str), st.floats(-50, 50).map(lambda x: f"{x:.3g}"))


@st.composite
def top_texts(draw):
    """TOP files: mostly well-formed (n matching the rows, numbers in every row) with one flaw at
    most, some with any tokens, some any text at all."""
    kind = draw(st.sampled_from(["any text", "tokens", "near valid", "near valid", "near valid"]))
    if kind == "any text":
        return draw(st.text(max_size=200))
    token = TOKENS if kind == "tokens" else NUMERIC
    rows = [" ".join(draw(st.lists(token, min_size=3, max_size=3))) for _ in range(draw(st.integers(0, 7)))]
    header = [f"n {len(rows)}", f"m {draw(st.integers(1, 4))}", f"tmax {draw(NUMERIC)}"]
    if kind == "near valid" and draw(st.booleans()):  # one flaw: a header or a row of any tokens
        spot = draw(st.integers(0, 2 + len(rows)))
        flaw = " ".join(draw(st.lists(TOKENS, min_size=0, max_size=4)))
        if spot < 3:
            header[spot] = header[spot].split()[0] + " " + flaw
        else:
            rows[spot - 3] = flaw
    if kind == "tokens":
        header = [" ".join([k] + draw(st.lists(TOKENS, max_size=2))) for k in ("n", "m", "tmax")]
    return "\n".join(header + rows) + draw(st.sampled_from(["", "\n"]))


@FAST
@given(top_texts())
def test_any_top_file_text_is_an_instance_or_one_instance_error(text):
    """Any TOP-file text is read as an instance or refused with one InstanceError line, nothing else."""
    path = WORK / "any.txt"
    path.write_bytes(text.encode("utf-8", "surrogatepass"))  # a lone surrogate makes it not UTF-8
    with strict():
        for read in (read_top, load_instance):  # load_instance also decides JSON or TOP by content
            try:
                top = read(path)
            except InstanceError as exc:
                one_line(exc)
                event(f"{read.__name__} refused")
            else:
                check_accepted(top)
                event(f"{read.__name__} accepted")


# -- the CLI --------------------------------------------------------------------------------------
def _files() -> dict[str, str]:
    files = {"good": sar_to_dict(generate(3, 2, 2, seed=1)),
             "infeasible": sar_to_dict(generate(3, 2, 1, seed=1, e_max=50)),  # exit 3 (proven)
             "crowded": sar_to_dict(generate(12, 1, 1, seed=0))}  # exit 3 (greedy finds no plan)
    out = {}
    for name, data in files.items():
        (WORK / f"{name}.json").write_text(json.dumps(data))
        out[name] = str(WORK / f"{name}.json")
    (WORK / "bad.json").write_text('{"format": "sarcover-instance", "version": 1}')
    (WORK / "top.txt").write_text("n 4\nm 1\ntmax 10\n0 0 0\n1 1 5\n2 2 3\n0 0 0\n")
    (WORK / "folder").mkdir(exist_ok=True)
    return {**out, "bad": str(WORK / "bad.json"), "top": str(WORK / "top.txt"), "folder": str(WORK / "folder"),
            "missing": str(WORK / "missing.json"), "name": "p2.2.a"}


FILES = _files()
free_text = st.text(alphabet=st.characters(blacklist_characters=":\x00", blacklist_categories=("Cs",)), max_size=10)
values = st.one_of(numbers.map(str), free_text, st.sampled_from(list(FILES.values()) + ["-1", "0", "nan", "1e400"]))
SOLVE_OPTIONS = st.sampled_from(["--method", "--method", "--time-limit", "--seed", "--json", "--json", "--plot",
                                 "--help", "--nope"])
GENERATE_OPTIONS = st.sampled_from(["--seed", "--preset", "--altitude", "--pitch-deg", "--e-fly", "--e-image",
                                    "--e-max", "--targets", "--nope"])
# ad hoc methods of the tests only (tests/bench_methods.py): free text never names a module
METHOD_NAMES = ["greedy", "greedy", "nope", "", "bench_methods:crash", "bench_methods:all_but_last"]
sizes = st.sampled_from(["1", "2", "3", "4", "5", "1", "2", "3", "0", "-1", "x", "1000000", "1000000000",
                         str(10**40)])


@st.composite
def argument_lists(draw):
    """`solve FILE` and `generate -M -K -N -o` (each part usually there), options in any order with
    mostly sensible and sometimes any values, sometimes a stray token anywhere; or other commands."""
    command = draw(st.sampled_from(["solve"] * 5 + ["generate"] * 3 + ["methods", "--version", "x"]))
    argv = [command]
    if command == "solve":
        if draw(st.integers(0, 5)):
            argv.append(draw(st.sampled_from(list(FILES.values()))))
    elif command == "generate":
        for flag, value in (("-M", sizes), ("-K", sizes), ("-N", sizes),
                            ("-o", st.sampled_from([str(WORK / "out.json"), "rel.json", str(WORK / "folder"),
                                                    str(WORK / "no" / "x.json")]))):
            if draw(st.integers(0, 7)):
                argv += [flag, draw(value)]
    options = SOLVE_OPTIONS if command == "solve" else GENERATE_OPTIONS
    for _ in range(draw(st.integers(0, 4)) if command in ("solve", "generate") else 0):
        option = draw(options)
        argv.append(option)
        if option == "--method":
            argv.append(draw(st.one_of(st.sampled_from(METHOD_NAMES), free_text)))
        elif option == "--plot":
            argv.append(draw(st.sampled_from([str(WORK / "p.png"), str(WORK / "p.xyz"), str(WORK / "folder"),
                                              str(WORK / "no" / "p.png")])))
        elif option in ("--time-limit", "--seed", "--altitude", "--e-fly", "--e-image", "--e-max", "--pitch-deg"):
            argv.append(draw(st.sampled_from(["1", "5", "45", "9000", "1", "5", "45", "9000", "0", "-3", "nan", "1e400",
                                              "1e300", "x", ""])))
        elif option == "--preset":
            argv.append(draw(st.sampled_from(["paper", "paper", "other"])))
        elif option not in ("--json", "--help", "--nope"):
            argv.append(draw(values))
    if draw(st.integers(0, 5)) == 0:
        argv.insert(draw(st.integers(1, len(argv))), draw(values))  # a stray token
    return argv


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(argument_lists())
@example(["methods", "\x1e"])  # a line break of str.splitlines in an argument
@example(["generate", "-M", "3", "-K", "2", "-N", "1", "-o", "\x00"])
def test_any_argument_list_gives_a_documented_exit_code_and_at_most_one_stderr_line(argv):
    """Any argument list exits with a documented code and at most one stderr line, never a traceback."""
    out, err = io.StringIO(), io.StringIO()
    cwd = os.getcwd()
    os.chdir(WORK)  # relative -o names land in the scratch folder
    try:
        with strict(), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(argv)
    finally:
        os.chdir(cwd)
    event(f"{argv[0]} exit {code}")
    assert code in SOLVE_CODES if argv[0] == "solve" else code in (EXIT_OK, EXIT_BAD_INPUT), (argv, code)
    lines = err.getvalue().splitlines()
    assert "Traceback" not in err.getvalue() and len(lines) <= 1, (argv, lines)
    if code == EXIT_BAD_INPUT:
        assert len(lines) == 1 and lines[0].startswith("sarcover: error: "), (argv, lines)
    if argv[0] == "solve" and code != EXIT_BAD_INPUT and "--json" in argv and not {"-h", "--help"} & set(argv):
        assert isinstance(json.loads(out.getvalue()), dict)
