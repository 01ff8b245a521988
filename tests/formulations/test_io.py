"""Instance files: JSON round trip and validation, TOP benchmark reader, generator."""

import json

import numpy as np
import pytest

from conftest import TOP_DIR
from sarcover.formulations.errors import InstanceError
from sarcover.formulations.generate import generate
from sarcover.formulations.io import load_instance, load_sar, read_top, save_json, sar_to_dict


def test_json_round_trip(tmp_path):
    """A generated instance saved and loaded is the same instance."""
    sar = generate(7, 3, 2, seed=11)
    save_json(sar, tmp_path / "a.json")
    back = load_sar(tmp_path / "a.json")
    np.testing.assert_array_equal(back.targets, sar.targets)
    assert (back.n_views, back.n_uavs, back.e_max, back.name) == (3, 2, sar.e_max, sar.name)


def test_generator_is_seeded_and_in_area():
    """Same seed, same targets; targets lie in the 2000 m square."""
    a, b, c = generate(20, 3, 5, seed=1), generate(20, 3, 5, seed=1), generate(20, 3, 5, seed=2)
    np.testing.assert_array_equal(a.targets, b.targets)
    assert not np.array_equal(a.targets, c.targets)
    assert a.targets.min() >= 0 and a.targets.max() <= 2000


def _bad(tmp_path, mutate):
    data = sar_to_dict(generate(3, 2, 1, seed=0))
    mutate(data)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize(
    "mutate, field",
    [
        (lambda d: d.pop("e_max"), "e_max"),
        (lambda d: d.update(e_fly=float("nan")), "e_fly"),
        (lambda d: d.update(e_image=-1.0), "e_image"),
        (lambda d: d.update(e_max=0), "e_max"),
        (lambda d: d.update(views=0), "views"),
        (lambda d: d.update(uavs=0), "uavs"),
        (lambda d: d.update(uavs=1.5), "uavs"),
        (lambda d: d["targets"].__setitem__(1, ["a", 2]), "targets[1]"),
        (lambda d: d.update(targets=[]), "targets"),
        (lambda d: d.update(version=99), "version"),
        (lambda d: d.update(altitude="high"), "altitude"),
    ],
)
def test_bad_json_names_the_field(tmp_path, mutate, field):
    """Each malformed field gives one InstanceError line that names it."""
    with pytest.raises(InstanceError) as err:
        load_sar(_bad(tmp_path, mutate))
    msg = str(err.value)
    assert field in msg and "\n" not in msg


def test_not_json(tmp_path):
    """A file that is not JSON is named as such."""
    p = tmp_path / "x.json"
    p.write_text("{not json")
    with pytest.raises(InstanceError, match="not valid JSON"):
        load_instance(p)


def test_top_reader_on_shipped_file():
    """p2.2.a: 21 points (19 customers), 2 vehicles, tmax 7.5, depots at first and last row."""
    inst = read_top(TOP_DIR / "p2.2.a.txt")
    rows = [ln.split() for ln in (TOP_DIR / "p2.2.a.txt").read_text().splitlines()[3:] if ln.strip()]
    assert inst.n_nodes == 19 and inst.n_vehicles == 2 and inst.budget == 7.5
    assert inst.e_fly == 1.0 and inst.e_image == 0.0 and inst.groups == ()
    np.testing.assert_allclose(inst.start, [float(rows[0][0]), float(rows[0][1])])
    np.testing.assert_allclose(inst.end, [float(rows[-1][0]), float(rows[-1][1])])
    assert inst.total_prize == sum(float(r[2]) for r in rows)


def test_all_shipped_top_files_parse():
    """Every shipped TOP file parses, and optimal.csv has a row for each."""
    import csv

    names = {p.stem for p in TOP_DIR.glob("p*.txt")}
    with open(TOP_DIR / "optimal.csv") as f:
        rows = {r["instance"]: r for r in csv.DictReader(f)}
    assert names == set(rows) and len(names) == 309
    size = {"p1": 32, "p2": 21, "p3": 33, "p4": 100, "p5": 66, "p6": 64, "p7": 102}  # points, both depots
    for p in TOP_DIR.glob("p*.txt"):
        inst = read_top(p)
        assert inst.n_nodes + 2 == size[p.stem[:2]]
        assert rows[p.stem]["status"] in ("optimal", "best_known")


def test_bad_top_file(tmp_path):
    """A TOP file whose header and rows disagree is rejected naming the problem."""
    p = tmp_path / "t.txt"
    p.write_text("n 4\nm 1\ntmax 3\n0 0 0\n1 1 5\n2 2 0\n")
    with pytest.raises(InstanceError, match="n 4 points, file has 3"):
        read_top(p)
