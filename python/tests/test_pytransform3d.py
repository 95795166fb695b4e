"""One comparison with pytransform3d's uncertainty functions on the same inputs.

pytransform3d's `concat_globally_uncertain_transforms(mean_A2B, cov_A2B, mean_B2C, cov_B2C)`
is Barfoot & Furgale's fourth-order compounding (eq. 55) of T_CA = T_CB T_BA with globally
(left) uncertain inputs, T = Exp(xi) T_bar, over exponential coordinates in rotation-first
order [omega; v]. posecov's `compose(method="fourth_order")` is the same formula in the
translation-first order [rho; theta]: `order="rotation_first"` converts at the boundary.
"""

import numpy as np
import pytest

from posecov import SE3, UncertainPose

uncertainty = pytest.importorskip("pytransform3d.uncertainty")


def spd(rng, scale):
    a = rng.normal(size=(6, 6)) * scale
    return a @ a.T + np.eye(6) * scale**2


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_fourth_order_equals_concat_globally_uncertain_transforms(seed):
    rng = np.random.default_rng(seed)
    mean_a2b = SE3.exp(rng.normal(size=6))
    mean_b2c = SE3.exp(rng.normal(size=6))
    cov_a2b = spd(rng, 0.05)  # rotation first, [omega; v]
    cov_b2c = spd(rng, 0.08)
    mean_a2c, cov_a2c = uncertainty.concat_globally_uncertain_transforms(mean_a2b, cov_a2b, mean_b2c, cov_b2c)

    b2c = UncertainPose("SE3", mean_b2c, cov_b2c, side="left", order="rotation_first")
    a2b = UncertainPose("SE3", mean_a2b, cov_a2b, side="left", order="rotation_first")
    a2c = b2c.compose(a2b, method="fourth_order")  # T_CA = T_CB T_BA
    assert a2c.side == "left"
    np.testing.assert_allclose(a2c.mean, mean_a2c, atol=1e-12)
    np.testing.assert_allclose(a2c.cov_in("rotation_first"), cov_a2c, rtol=1e-9, atol=1e-12)
    # The second-order part alone differs from the fourth order by O(Sigma^2).
    second = b2c.compose(a2b, method="second_order").cov_in("rotation_first")
    assert 0 < np.linalg.norm(second - cov_a2c) < 0.1 * np.linalg.norm(cov_a2c)
