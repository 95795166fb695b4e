"""The reference cases of docs/REFERENCE_CASES.md, from Python, through the wheel.

R1 (closed forms), R2 (NA 568 SE(2) odometry), R3 (right against left form), R4 (ROB 530
SE(3) odometry with Jr), R5 (Barfoot & Furgale's repeated compounding). R6 (the
Gauss-Hermite oracle) and R7 (the differential drive's closed forms) test library internals
that the package does not expose; `cargo test` runs them.
"""

import numpy as np
import pytest

import posecov
from posecov import SE2, SE3, SO3, UncertainPose

# ---------------------------------------------------------------------------------------
# R1: closed-form fixtures, 1e-8 on every entry; Jacobians within 1e-6 of finite differences.

SO3_PHI = [0.1, 0.2, 0.3]


def test_r1_so3():
    np.testing.assert_allclose(
        SO3.exp(SO3_PHI),
        [[0.935754803, -0.283164961, 0.210191706], [0.302932713, 0.950580618, -0.068031316],
         [-0.180540077, 0.127334575, 0.975290309]], atol=1e-8)
    np.testing.assert_allclose(
        SO3.jl(SO3_PHI),
        [[0.978484495, -0.144948069, 0.103803881], [0.151568224, 0.983449612, -0.039489149],
         [-0.093873648, 0.059349615, 0.991724806]], atol=1e-8)
    np.testing.assert_allclose(
        SO3.jl_inv(SO3_PHI),
        [[0.989141304, 0.151670569, -0.097494147], [-0.148329431, 0.991647157, 0.055011706],
         [0.102505853, -0.044988294, 0.995823579]], atol=1e-8)
    np.testing.assert_allclose(
        SO3.jr([1, -2, 0.5]),
        [[0.455978492, -0.0979383, 0.696289814], [-0.414081942, 0.839993674, 0.188138581],
         [-0.568284754, -0.444148703, 0.359974696]], atol=1e-8)


def test_r1_se3():
    xi = [1, -0.5, 2, 0.1, 0.2, 0.3]
    np.testing.assert_allclose(SE3.exp(xi)[:3, 3], [1.258566291, -0.41913488, 1.859901157], atol=1e-8)
    ad = SE3.adjoint(SE3.exp(xi))
    np.testing.assert_allclose(
        ad[:3, 3:],
        [[-0.487754261, -1.821356353, -0.282246663], [1.967633096, -0.686917841, -0.83653171],
         [0.773468379, 1.077684411, 0.002476754]], atol=1e-8)
    # The tangent order is [rho; theta]: Log returns it, the adjoint's rotation block is R.
    np.testing.assert_allclose(SE3.log(SE3.exp(xi)), xi, atol=1e-12)
    np.testing.assert_allclose(ad[3:, 3:], SE3.exp(xi)[:3, :3], atol=1e-15)


def test_r1_se2():
    tau = [1, 2, 0.5]
    np.testing.assert_allclose(
        SE2.exp(tau),
        [[0.877582562, -0.479425539, 0.469181325], [0.479425539, 0.877582562, 2.162537031], [0, 0, 1]],
        atol=1e-8)
    np.testing.assert_allclose(
        SE2.jr(tau),
        [[0.958851077, 0.244834876, -0.897041659], [-0.244834876, 0.958851077, 0.654265444], [0, 0, 1]],
        atol=1e-8)
    np.testing.assert_allclose(
        SE2.jl(tau),
        [[0.958851077, -0.244834876, 1.06163735], [0.244834876, 0.958851077, -0.325074061], [0, 0, 1]],
        atol=1e-8)
    np.testing.assert_allclose(
        SE2.adjoint(SE2.exp(tau)),
        [[0.877582562, -0.479425539, 2.162537031], [0.479425539, 0.877582562, -0.469181325], [0, 0, 1]],
        atol=1e-8)


@pytest.mark.parametrize("group,tau", [(SE2, [1, 2, 0.5]), (SE3, [1, -0.5, 2, 0.1, 0.2, 0.3]),
                                       (SO3, [1, -2, 0.5])])
def test_r1_jr_against_finite_differences(group, tau):
    """Exp(tau + d) ~ Exp(tau) Exp(Jr d): column k of Jr is (Log(Exp(tau)^-1 Exp(tau + h e_k)) - ...) / 2h."""
    tau = np.asarray(tau, dtype=float)
    h = 1e-6
    x = group.exp(tau)
    numeric = np.column_stack([
        (group.rminus(group.exp(tau + h * e), x) - group.rminus(group.exp(tau - h * e), x)) / (2 * h)
        for e in np.eye(len(tau))
    ])
    np.testing.assert_allclose(group.jr(tau), numeric, atol=1e-6)


@pytest.mark.parametrize("theta", [0.0, 1e-8, np.pi - 1e-6])
def test_r1_singular_branches(theta):
    tau = np.array([0.3, -0.2, 0.1, 0.0, 0.0, theta])
    np.testing.assert_allclose(SE3.log(SE3.exp(tau)), tau, atol=1e-9)
    phi = np.array([0.0, theta, 0.0])
    np.testing.assert_allclose(SO3.log(SO3.exp(phi)), phi, atol=1e-9)


# ---------------------------------------------------------------------------------------
# R2 / R3: SE(2) odometry X_{k+1} = X_k U_k Exp(w_k), right form, deterministic to 1e-6.

U2 = [0.043333, 0.062110, 0.089025, 0.127602, 0.182895, 0.262149, 0.375746]
U3 = [0.072096, 0.031054, 0.044150, 0.062248, 0.086330, 0.116042, 0.147573]
SIGMA_W = np.diag([0.03**2, 0.03**2, 0.1**2])


def increment(k):
    """U_k = [[R(u3), (u1, u2)], [0, 1]]: its translation as given (not V rho)."""
    c, s = np.cos(U3[k]), np.sin(U3[k])
    return np.array([[c, -s, 0.6], [s, c, U2[k]], [0, 0, 1.0]])


def na568(steps):
    x = UncertainPose("SE2", np.eye(3), np.zeros((3, 3)))
    for k in range(steps):
        x = x.compose(UncertainPose("SE2", increment(k), SIGMA_W))
    return x


def upper(rows):
    """A symmetric matrix from its upper triangle, row by row."""
    (a, b, c), (d, e), (f,) = rows
    return np.array([[a, b, c], [b, d, e], [c, e, f]])


def test_r2_na568_odometry():
    x2 = na568(2)
    np.testing.assert_allclose(x2.cov, upper([(0.001819, -0.000261, -0.000435), (0.005420, 0.006016), (0.02,)]), atol=1e-6)
    x7 = na568(7)
    assert x7.side == "right"
    np.testing.assert_allclose(SE2.log(x7.mean)[2], 0.559493, atol=1e-6)
    np.testing.assert_allclose(x7.mean[:2, 2], [3.802082, 1.827062], atol=5e-6)  # printed to 6 digits
    np.testing.assert_allclose(x7.cov, upper([(0.010612, -0.013364, -0.010833), (0.358141, 0.131531), (0.07,)]), atol=1e-6)


def test_r2_monte_carlo_agrees():
    """One step of R2 against seeded Monte Carlo (2e4 samples; the case asks 1.5 % at 1e5)."""
    x1 = na568(1)
    u = UncertainPose("SE2", increment(1), SIGMA_W)
    first = x1.compose(u).cov
    mc = x1.monte_carlo_compose(u, 20000, seed=4).cov
    assert np.linalg.norm(mc - first) / np.linalg.norm(first) < 0.05


def test_r3_right_against_left():
    x6 = na568(6)
    np.testing.assert_allclose(x6.mean, [[0.916354, -0.400369, 3.402707], [0.400369, 0.916354, 1.242525], [0, 0, 1]], atol=1e-6)
    left = np.array([[0.031276, -0.085458, 0.030631], [-0.085458, 0.310709, -0.122399], [0.030631, -0.122399, 0.06]])
    np.testing.assert_allclose(x6.to_side("left").cov, left, atol=1e-6)
    ad = SE2.adjoint(x6.mean)
    np.testing.assert_allclose(x6.to_side("left").cov, ad @ x6.cov @ ad.T, atol=1e-12)


# ---------------------------------------------------------------------------------------
# R4: SE(3) odometry with the noise inside Exp, X_{k+1} = X_k Exp(u_k + w_k), Jr kept.

def test_r4_rob530_with_jr():
    v1 = np.array([0, 1.333333, 2.666667, 4])
    v2 = 1.5 * v1
    v3 = 0.05 * np.exp(0.6 * v1) - 0.05
    w1 = np.array([0, 1 / 6, 1 / 3, 0.5])
    w2 = np.array([0, 0.1, 0.2, 0.3])
    w3 = np.array([0, 0.7 / 3, 1.4 / 3, 0.7])
    sigma_w = np.diag([0.01**2, 0.01**2, 0.05**2, 0.05**2, 0.05**2, 0.2**2])
    x = UncertainPose("SE3", np.eye(4), np.zeros((6, 6)))
    for k in range(4):
        u = np.array([v1[k], v2[k], v3[k], w1[k], w2[k], w3[k]])
        jr = SE3.jr(u)
        x = x.compose(UncertainPose("SE3", SE3.exp(u), jr @ sigma_w @ jr.T))
    np.testing.assert_allclose(x.mean[:3, 3], [0.460708, 11.663701, 6.289424], atol=1e-5)
    np.testing.assert_allclose(np.diag(x.cov), [0.867324, 5.207498, 9.044747, 0.012427, 0.081679, 0.083749], atol=1e-6)


# ---------------------------------------------------------------------------------------
# R5: Barfoot & Furgale 2014 Fig. 2, a hundred steps, second and fourth order, left form.

@pytest.mark.parametrize("method", ["second_order", "fourth_order"])
def test_r5_barfoot_compounding(method):
    step = UncertainPose("SE3", SE3.exp([1, 0, 0, 0, 0, 0]), np.diag([0, 0, 0, 0, 0, 0.0009]), side="left")
    t = UncertainPose("SE3", np.eye(4), np.zeros((6, 6)), side="left")
    for _ in range(100):
        t = step.compose(t, method=method)
    assert t.side == "left"
    np.testing.assert_allclose(t.mean[:3, 3], [100, 0, 0], atol=1e-9)
    cov = t.cov
    np.testing.assert_allclose([cov[1, 5], cov[5, 5]], [-4.455, 0.09], atol=1e-6)  # rho_y theta_z
    if method == "second_order":
        np.testing.assert_allclose([cov[0, 0], cov[1, 1]], [0.0, 295.515], atol=1e-6)
    else:
        np.testing.assert_allclose([cov[0, 0], cov[1, 1]], [1.677522, 294.400746], atol=1e-6)


def test_sigma_points_equal_first_order_for_compose():
    """CONVENTIONS / sigma_point docs: for compose of independent inputs, inside pi, the
    unscented covariance equals the first-order one."""
    a = UncertainPose("SE3", SE3.exp([1, 0, 0, 0, 0, 0.3]), np.eye(6) * 1e-3)
    b = UncertainPose("SE3", SE3.exp([0, 1, 0, 0.2, 0, 0]), np.eye(6) * 2e-3)
    np.testing.assert_allclose(a.compose(b, method="sigma_points").cov, a.compose(b).cov, atol=1e-12)
    points, wm, wc = a.sigma_points()
    assert points.shape == (13, 4, 4) and abs(wm.sum() - 1) < 1e-12
    np.testing.assert_allclose(points[0], a.mean)


def test_sampling_is_seeded():
    a = UncertainPose("SE2", SE2.exp([1, 2, 0.3]), np.diag([0.01, 0.02, 0.003]))
    s1, s2, s3 = a.sample(5000, seed=9), a.sample(5000, seed=9), a.sample(5000, seed=10)
    assert np.array_equal(s1, s2) and not np.array_equal(s1, s3)
    eps = np.array([SE2.rminus(x, a.mean) for x in s1])
    np.testing.assert_allclose(np.cov(eps.T), a.cov, rtol=0.1, atol=1e-3)
