//! Scenarios besides the bundled ones, so that mutants start from every operation kind.

/// Seeds besides the bundled scenarios, for what none of them uses: SO(2), `point_through_pose`,
/// `fuse`, `between`, `compose_correlated`, `between_correlated`, `odometry` with `steps`.
pub const EXTRA_SEEDS: &[(&str, &str)] = &[
    (
        "extra_se3",
        r#"[scenario]
title = "extra: points, fusion, correlated (SE(3))"
group = "se3"
seed = 3
samples = 500
methods = ["first_order", "second_order", "fourth_order", "sigma_points", "monte_carlo", "vector_space"]

[[pose]]
name = "world_from_a"
mean = { xyz = [1.0, 0.0, 0.0], rpy = [0.0, 0.0, 0.3] }
cov = { std = [0.1, 0.1, 0.1, 0.05, 0.05, 0.2] }

[[pose]]
name = "world_from_b"
mean = { xyz = [1.1, 0.1, 0.0], rpy = [0.0, 0.1, 0.35] }
cov = { std = [0.2, 0.1, 0.1, 0.05, 0.05, 0.1] }

[[pose]]
name = "a_from_sensor"
mean = { xyz = [0.5, 0.0, 0.2], quaternion_xyzw = [0.0, 0.0, 0.0, 1.0] }

[[operation]]
kind = "point_through_pose"
input = "world_from_a"
point = [2.0, 0.0, 0.0]
point_cov = [[0.01, 0.0, 0.0], [0.0, 0.01, 0.0], [0.0, 0.0, 0.01]]
output = "landmark"

[[operation]]
kind = "fuse"
inputs = ["world_from_a", "world_from_b"]
output = "world_from_fused"

[[operation]]
kind = "between"
lhs = "world_from_a"
rhs = "world_from_b"
output = "a_from_b"

[[operation]]
kind = "compose_correlated"
lhs = "world_from_a"
rhs = "a_from_b"
cross_cov = [[0.001, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]]
output = "world_from_b2"

[[operation]]
kind = "change_frame_right"
input = "world_from_a"
by = "a_from_sensor"
output = "world_from_sensor"

[[operation]]
kind = "odometry"
input = "world_from_a"
model = "exp"
controls = [[0.5, 0.0, 0.0, 0.0, 0.0, 0.1]]
steps = 5
noise = { std = [0.01, 0.01, 0.01, 0.01, 0.01, 0.02] }
output = "world_from_robot"
"#,
    ),
    (
        "extra_se2",
        r#"[scenario]
title = "extra: points, fusion, correlated (SE(2))"
group = "se2"
seed = 4
samples = 300
methods = ["first_order", "sigma_points", "monte_carlo", "vector_space", "lecture_no_jr"]

[[pose]]
name = "map_from_a"
mean = { xy_theta = [1.0, 2.0, 0.3] }
cov = { std = [0.1, 0.2, 0.1] }

[[pose]]
name = "map_from_b"
mean = { xy_theta_deg = [1.2, 2.1, 20.0] }
cov = { matrix = [[0.02, 0.001, 0.0], [0.001, 0.03, 0.0], [0.0, 0.0, 0.01]], side = "left" }

[[operation]]
kind = "point_through_pose"
input = "map_from_a"
point = [1.0, 0.5]
output = "corner"

[[operation]]
kind = "fuse"
inputs = ["map_from_a", "map_from_b"]
output = "map_from_fused"

[[operation]]
kind = "between_correlated"
lhs = "map_from_a"
rhs = "map_from_b"
cross_cov = [[0.001, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
output = "a_from_b"

[[operation]]
kind = "odometry"
input = "map_from_fused"
model = "increment"
controls = [[0.3, 0.0, 0.1], [0.3, 0.0, -0.1]]
noise = { std_deg = [0.01, 0.01, 1.0] }
output = "map_from_robot"
"#,
    ),
    (
        "extra_so2",
        r#"[scenario]
title = "extra: SO(2)"
group = "so2"
seed = 5
samples = 200
methods = ["first_order", "sigma_points", "monte_carlo"]

[[pose]]
name = "world_from_dial"
mean = { angle_deg = 30.0 }
cov = { std_deg = [10.0] }

[[pose]]
name = "dial_from_needle"
mean = { angle = 0.5 }

[[operation]]
kind = "change_frame_right"
input = "world_from_dial"
by = "dial_from_needle"
output = "world_from_needle"

[[operation]]
kind = "inverse"
input = "world_from_needle"
output = "needle_from_world"

[[operation]]
kind = "point_through_pose"
input = "world_from_dial"
point = [1.0, 0.0]
point_cov = [[0.01, 0.0], [0.0, 0.01]]
output = "tip"

[[operation]]
kind = "compound"
input = "world_from_dial"
by = "dial_from_needle"
steps = 3
noise = { std = [0.05] }
output = "spun"
"#,
    ),
];
