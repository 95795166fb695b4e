"""Every input the library refuses raises PosecovError (a ValueError) naming what is wrong;
nothing crashes the interpreter (each case runs in this process)."""

import math

import numpy as np
import pytest

import posecov
from posecov import SE2, SE3, SO3, PosecovError, UncertainPose


@pytest.mark.parametrize("call,match", [
    (lambda: SE3.exp([1, 2, 3]), r"tau: expected an array of shape \(6,\), got shape \(3,\)"),
    (lambda: SE3.exp(np.zeros((6, 1))), r"shape \(6, 1\)"),
    (lambda: SE3.log(np.eye(3)), r"x: expected an array of shape \(4, 4\), got shape \(3, 3\)"),
    (lambda: SE2.compose(np.eye(3), "abc"), r"y: not an array of numbers"),
    (lambda: SE2.exp([1, math.nan, 0]), r"tau: element 1 is NaN, but every element must be finite"),
    (lambda: SE2.exp([1, math.inf, 0]), r"element 1 is inf"),
    (lambda: SO3.log(np.diag([1.0, 1.0, -1.0])), r"x: .*determinant"),
    (lambda: SO3.log(np.ones((3, 3))), r"x: "),
    (lambda: SE3.inverse(np.ones((4, 4))), r"x: "),
    (lambda: SO3.from_quaternion([0, 0, 0, 2]), r"quaternion .* has norm 2\.0"),
    (lambda: SE3.from_xyz_quaternion([0, 0, 0], [0.1, 0.1, 0.1, 0.1]), r"quaternion"),
    (lambda: SO3.from_quaternion([0, 0, 1]), r"xyzw: expected an array of shape \(4,\)"),
    (lambda: SE2.interpolate(np.eye(3), np.eye(3), math.nan), r"t: NaN is not finite"),
])
def test_lie_inputs(call, match):
    with pytest.raises(PosecovError, match=match):
        call()


def test_posecov_error_is_a_value_error():
    assert issubclass(PosecovError, ValueError)


@pytest.mark.parametrize("args,match", [
    (("SE3", np.eye(4), -np.eye(6)), r"not positive semi-definite"),
    (("SE3", np.eye(4), np.eye(6) + np.triu(np.ones((6, 6)), 1)), r"not symmetric"),
    (("SE3", np.eye(4), np.full((6, 6), math.nan)), r"cov: element 0 is NaN"),
    (("SE3", np.eye(4), np.eye(3)), r"cov: expected an array of shape \(6, 6\)"),
    (("SE2", np.eye(4), np.eye(3)), r"mean: expected an array of shape \(3, 3\)"),
    (("SE9", np.eye(4), np.eye(6)), r"group"),
])
def test_uncertain_pose_inputs(args, match):
    with pytest.raises(PosecovError, match=match):
        UncertainPose(*args)


def test_uncertain_pose_options():
    x = UncertainPose("SE2", np.eye(3), np.eye(3) * 0.01)
    with pytest.raises(PosecovError, match="side"):
        UncertainPose("SE2", np.eye(3), np.eye(3), side="up")
    with pytest.raises(PosecovError, match="order"):
        UncertainPose("SE2", np.eye(3), np.eye(3), order="sideways")
    with pytest.raises(PosecovError, match="cannot be combined"):
        x.compose(UncertainPose("SO3", np.eye(3), np.eye(3)))
    with pytest.raises(PosecovError, match="method"):
        x.compose(x, method="magic")
    with pytest.raises(PosecovError, match="SE\\(2\\) and SE\\(3\\)"):
        UncertainPose("SO3", np.eye(3), np.eye(3)).compose(UncertainPose("SO3", np.eye(3), np.eye(3)), method="fourth_order")
    with pytest.raises(PosecovError, match="samples"):
        x.sample(0)
    with pytest.raises(PosecovError):
        x.sigma_points(alpha=-1.0)
    with pytest.raises(PosecovError):
        x.compose(x, method="sigma_points", alpha=math.nan)


def test_unknown_bundled_name_says_what_exists():
    with pytest.raises(PosecovError) as e:
        posecov.report("camera_on_robott")
    assert "camera_on_robot" in str(e.value) and e.value.exit_code == 2
    with pytest.raises(PosecovError):
        posecov.check("no/such/file.bag")
    with pytest.raises(PosecovError):
        posecov.figure("no_such_example", "x.svg")


def test_damaged_logs(tmp_path, root):
    for name, data in [
        ("empty.bag", b""),
        ("zeros.mcap", b"\x89MCAP0\r\n" + b"\x00" * 64),
        ("half.bag", (root / "tests/data/robot_localization/test2.bag").read_bytes()[:5000]),
        ("garbage.db3", b"SQLite format 3\x00" + b"\xff" * 200),
    ]:
        path = tmp_path / name
        path.write_bytes(data)
        try:
            posecov.report(path)
        except PosecovError as e:
            assert str(e) and e.exit_code in (1, 2)
        verdict = None
        try:
            verdict = posecov.check(path)
        except PosecovError:
            pass
        assert verdict is None or verdict["exit_code"] in (0, 1)
