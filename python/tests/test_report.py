"""report(), check() and figure() against the command line on the same inputs."""

import json
import shutil

import pytest

import posecov
from conftest import comparable

PLANS = ["camera_on_robot", "so3_sampling", "gtsam_pose2example"]


@pytest.mark.parametrize("name", PLANS + ["jackal_odometry", "covariance_health"])
def test_report_equals_cli_json_for_bundled(name, cli_json):
    code, expected, _ = cli_json(name, "--samples", 300)
    assert code == 0
    got = posecov.report(name, samples=300)
    assert got["schema_version"] == posecov.REPORT_SCHEMA_VERSION == expected["schema_version"]
    assert comparable(got) == comparable(expected)


def test_report_of_files(root, cli_json):
    """A scenario file, a pose graph file and a log file, with flags as keywords."""
    scenario = root / "assets/scenarios/na568_se2_odometry.toml"
    assert posecov.report(scenario, seed=5, samples=200) == cli_json(scenario, "--seed", 5, "--samples", 200)[1]
    graph = root / "tests/data/gtsam/pose2example.txt"
    if graph.exists():
        got = posecov.report(graph, optimizer="gn", joint=(1, 3))
        assert comparable(got) == comparable(cli_json(graph, "--optimizer", "gn", "--joint", "1,3")[1])
    log = root / "tests/data/mcap/amcl_tf.mcap"
    assert posecov.report(log, every=3, ros_reading="body") == cli_json(log, "--every", 3, "--ros-reading", "body")[1]


def test_report_errors_carry_the_cli_message(cli):
    code, out, err = cli("report", "no_such_example", "--json")
    with pytest.raises(posecov.PosecovError) as e:
        posecov.report("no_such_example")
    assert e.value.exit_code == code == 2
    assert "error: " + str(e.value) == err.strip().splitlines()[0] or str(e.value) in err
    assert e.value.details == json.loads(out)["error"]


def test_located_scenario_error(tmp_path, cli):
    bad = tmp_path / "bad.toml"
    bad.write_text("[scenario]\ntitle = \"t\"\ngroup = \"se2\"\nsamples = 1\n")
    code, out, err = cli("report", bad, "--json")
    with pytest.raises(posecov.PosecovError) as e:
        posecov.report(bad)
    assert str(e.value).startswith(f"{bad}:4:11: scenario.samples: 1 is out of range")
    assert e.value.exit_code == code == 1
    assert (e.value.details["line"], e.value.details["column"]) == (4, 11)
    assert e.value.details == json.loads(out)["error"]
    assert f"error: {e.value}" in err


def test_damaged_log(tmp_path, root, cli):
    damaged = tmp_path / "cut.mcap"
    damaged.write_bytes((root / "tests/data/mcap/amcl_tf.mcap").read_bytes()[:700])
    code, out, err = cli("report", damaged, "--json")
    if code == 0:
        assert posecov.report(damaged) == json.loads(out)
        return
    with pytest.raises(posecov.PosecovError) as e:
        posecov.report(damaged)
    assert e.value.details == json.loads(out)["error"]
    garbage = tmp_path / "noise.mcap"
    garbage.write_bytes(b"\x89MCAP0\r\n" + bytes(range(256)) * 4)
    with pytest.raises(posecov.PosecovError):
        posecov.report(garbage)


def test_bad_overrides_are_refused():
    with pytest.raises(posecov.PosecovError, match="--samples 1: out of range"):
        posecov.report("camera_on_robot", samples=1)
    with pytest.raises(posecov.PosecovError, match="--confidence"):
        posecov.report("camera_on_robot", confidence=1.5)
    with pytest.raises(posecov.PosecovError, match="--every"):
        posecov.report("camera_on_robot", every=2)  # a flag for logs only, as the CLI says
    with pytest.raises(TypeError, match="unexpected keyword argument"):
        posecov.report("camera_on_robot", smaples=10)
    with pytest.raises(posecov.PosecovError, match="--ros-reading"):
        posecov.report("jackal_odometry", ros_reading="sideways")


@pytest.mark.parametrize("name", ["camera_on_robot", "covariance_health", "jackal_odometry"])
def test_check_equals_cli(name, cli):
    code, out, err = cli("check", name)
    got = posecov.check(name)
    assert got["line"] == out.strip()
    assert got["exit_code"] == code
    assert [d["text"] for d in got["defects"]] == [l for l in err.splitlines() if l.strip()]


def test_check_defect_classes_and_allow():
    got = posecov.check("covariance_health")
    assert not got["ok"]
    issues = {d["issue"] for d in got["defects"] if d["issue"]}
    assert issues and issues <= {
        "non_finite", "asymmetric", "not_psd", "undecodable", "bad_orientation", "unknown_marker",
        "all_zero", "placeholder_used_axis", "constant", "frozen_stamp", "type_change",
        "tf_cycle", "tf_several_parents",
    }
    assert all(d["topic"] for d in got["defects"] if d["issue"])
    with pytest.raises(posecov.PosecovError, match="--allow nan: out of range"):
        posecov.check("covariance_health", allow=["nan"])


def test_figure_matches_cli(tmp_path, cli):
    cli_svg, py_svg = tmp_path / "cli.svg", tmp_path / "py.svg"
    code, _, _ = cli("figure", "camera_on_robot", "-o", cli_svg, "--samples", 200, "--plane", "xz")
    assert code == 0
    posecov.figure("camera_on_robot", py_svg, samples=200, plane="xz")
    assert py_svg.read_text() == cli_svg.read_text()
    assert posecov.figure_svg("camera_on_robot", samples=200, plane="xz") == cli_svg.read_text()
    for ext, magic in [("png", b"\x89PNG"), ("pdf", b"%PDF")]:
        out = tmp_path / f"f.{ext}"
        posecov.figure("so3_sampling", out, samples=100, size=(320, 200))
        assert out.read_bytes().startswith(magic)
    with pytest.raises(posecov.PosecovError, match="--size"):
        posecov.figure("so3_sampling", tmp_path / "x.svg", size=(1, 1))
    with pytest.raises(posecov.PosecovError):
        posecov.figure("so3_sampling", tmp_path / "x.gif")


def test_figure_inline_svg():
    fig = posecov.Figure("so3_sampling", samples=100)
    assert fig._repr_svg_().startswith("<svg") and "</svg>" in fig.svg


def test_notebook_figure_and_viewer_needs():
    from posecov import notebook

    assert notebook.figure("so3_sampling", samples=100).svg == posecov.figure_svg("so3_sampling", samples=100)
    try:
        import rerun_notebook  # noqa: F401
    except ImportError:
        with pytest.raises(ImportError, match=r"pip install rerun-notebook==0\.36\.3"):
            notebook.viewer(b"")
    else:
        pytest.skip("rerun-notebook is installed: the missing-widget message cannot be seen")


def test_examples_and_expand(root):
    names = [n for n, _ in posecov.examples()]
    assert "camera_on_robot" in names and "jackal_odometry" in names
    logs = posecov.expand(root / "tests/data/mcap")
    assert [l.rsplit("/", 1)[1] for l in logs] == ["amcl_tf.mcap", "health_cases.mcap"]
