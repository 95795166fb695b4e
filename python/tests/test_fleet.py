"""The fleet example (python/examples/fleet_dask.py) on a real distributed.LocalCluster with two
worker processes, over the bundled logs, the committed ones and logs generated from them
(damaged copies among them), against `posecov report DIR... --json` on the same tree."""

import json
import shutil
import subprocess
import sys

import pytest

pytest.importorskip("distributed")


def make_tree(root, data):
    """robot_a: the two MCAP files and a cut copy; robot_b: the bundled bag, a ROS 2 bag
    directory, a .db3 file and a file that only looks like a bag; robot_b/day2: a copy."""
    a, b, day2 = root / "robot_a", root / "robot_b", root / "robot_b" / "day2"
    for d in (a, b, day2):
        d.mkdir(parents=True)
    shutil.copy(data / "mcap/amcl_tf.mcap", a / "amcl_tf.mcap")
    shutil.copy(data / "mcap/health_cases.mcap", a / "health_cases.mcap")
    (a / "cut_short.mcap").write_bytes((data / "mcap/health_cases.mcap").read_bytes()[:900])
    (a / "notes.txt").write_text("not a log")
    shutil.copy(data / "robot_localization/test2.bag", b / "jackal.bag")
    shutil.copytree(data / "ros2/arc_v9", b / "arc_v9")
    shutil.copy(data / "ros2/arc_humble/arc_humble_0.db3", b / "humble.db3")
    (b / "garbage.bag").write_bytes(b"#ROSBAG V2.0\n" + b"\x00" * 300)
    shutil.copy(data / "mcap/amcl_tf.mcap", day2 / "amcl_again.mcap")
    return [a, b, day2]


def by_scenario(lines):
    from conftest import comparable

    return {line["scenario"]: comparable(line) for line in lines}


def test_fleet_on_local_cluster_equals_cli(tmp_path, root, cli):
    dirs = make_tree(tmp_path / "fleet", root / "tests/data")
    out = tmp_path / "fleet.jsonl"
    run = subprocess.run(
        [sys.executable, str(root / "python/examples/fleet_dask.py"), str(tmp_path / "fleet"),
         "--out", str(out), "--workers", "2", "--samples", "50"],
        capture_output=True, text=True, timeout=900,
    )
    assert run.returncode in (1, 2), run.stderr  # defects and unreadable logs in the tree
    ours = [json.loads(line) for line in out.read_text().splitlines()]
    code, cli_out, _ = cli("report", *dirs, "--json", "--samples", 50)
    theirs = [json.loads(line) for line in cli_out.splitlines()]
    assert len(ours) == len(theirs) == 8
    assert by_scenario(ours) == by_scenario(theirs)
    errors = [l for l in ours if "error" in l]
    assert {l["scenario"].rsplit("/", 1)[1] for l in errors} >= {"garbage.bag"}
    # The summary: a verdict per log, the defect classes by topic, the unreadable logs counted.
    assert "verdict per log:" in run.stdout
    assert "defect" in run.stdout and "unreadable" in run.stdout
    code, check_out, _ = cli("check", *dirs, "--samples", 50)
    for line in check_out.splitlines():
        assert line in run.stdout
    assert run.returncode == code
