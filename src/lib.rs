//! # posecov — see what robot pose uncertainty really looks like
//!
//! posecov takes poses with covariances and the operations a robot applies to them (compose,
//! invert, change frame, propagate odometry, fuse), computes the resulting uncertainty with
//! every method the literature offers, and draws it — sampled clouds, covariance ellipsoids,
//! Exp-mapped "banana" surfaces, orientation sprays — in the Rerun viewer.
//!
//! This crate is the library behind the `posecov` binary. Data flows one way, through five
//! stages, each getting only its own settings and handing plain data to the next:
//!
//! 1. [`input`]: a file (TOML scenario, g2o / GTSAM / TORO pose graph, ROS 1 bag, MCAP) or a
//!    bundled example, its format decided once, read and checked with every error at its
//!    `file:line:column` → a typed [`plan`] ([`plan::Plan`]; a robot log:
//!    [`plan::log::LogSummary`]).
//! 2. [`eval`]: numbers only — every method's estimate, Monte Carlo statistics and typed
//!    findings ([`eval::Evaluation`]; logs: [`eval::log`]).
//! 3. [`draw`]: what to show — shapes, clouds, plots, text and views as plain data.
//! 4. [`scene`]: that plain data ([`scene::Scene`]), validated, knowing nothing of Rerun.
//! 5. `sink` (viewer feature): the scene to the Rerun viewer, an .rrd file, stdout or a web
//!    viewer.
//!
//! [`app`] resolves the settings once (flags over file over defaults) and runs the stages;
//! `ARCHITECTURE.md` says where each kind of change goes. The math underneath:
//!
//! - [`lie`]: the groups SO(2), SO(3), SE(2), SE(3) with exp/log, adjoints and every Jacobian.
//! - [`uncertain`]: poses with covariances (mean, Σ, side), validation, side conversion.
//! - [`propagate`]: operations on uncertain poses, each method named in its result.
//! - [`sample`]: seeded (parallel, thread-count independent) sampling; Lie mean, covariances, NEES.
//! - [`convert`]: nalgebra and glam boundaries.
//! - [`interop`]: uncertain poses in and out: ROS `PoseWithCovariance`, rotation-first orders, (x, y, θ) and Euler-angle covariances.
//! - [`error`]: typed errors that name the offending input and value.
//!
//! # Conventions
//!
//! One contract for every function whose result depends on a convention (the project's
//! `CONVENTIONS.md`; sources: Solà, Deray & Atchuthan 2018 "A micro Lie theory for state
//! estimation in robotics", arXiv:1812.01537; Barfoot & Furgale 2014, IEEE T-RO 30(3)).
//!
//! | topic | posecov's choice |
//! |---|---|
//! | numbers | `f64` nalgebra in the core; `f32` glam only for rendering |
//! | SO(2) tangent | θ (1 DOF), matrix 2×2 |
//! | SE(2) tangent | **[ρx, ρy, θ]** (3 DOF), matrix 3×3 |
//! | SO(3) tangent | θ ∈ ℝ³ = axis · angle (3 DOF), matrix 3×3 |
//! | SE(3) tangent | **[ρ (3); θ (3)] — translation first** (6 DOF), matrix 4×4 |
//! | perturbation side (default) | **right / local / body**: X = μ · Exp(ε), ε ~ N(0, Σ), Σ in the body frame at μ |
//! | the other side | left / global / world: X = Exp(ε) · μ; Σ_left = Ad_μ Σ_right Ad_μᵀ |
//! | adjoint | Ad_X τ = vee(X · hat(τ) · X⁻¹); SE(3): Ad = [[R, t^R], [0, R]]; SE(2): [[R, (t_y, −t_x)ᵀ], [0, 0, 1]] |
//! | Jacobians | with respect to **right** perturbations of inputs and output (Solà et al.): J_compose_lhs = Ad_Y⁻¹, J_compose_rhs = I, J_inverse = −Ad_X, J_rplus_X = Ad_{Exp τ}⁻¹, J_rplus_τ = Jr(τ) |
//! | Jr, Jl | Exp(τ + δ) ≈ Exp(τ) Exp(Jr(τ) δ) ≈ Exp(Jl(τ) δ) Exp(τ); Jl(τ) = Jr(−τ) = Ad_{Exp τ} Jr(τ) |
//! | Log | closed form, rotation angle \|θ\| ≤ π, stable at θ → 0 and θ → π (quaternion-based for SO(3)) |
//! | quaternion order | named at each boundary: nalgebra stores `[i, j, k, w]`, glam `from_xyzw`, ROS `(x, y, z, w)` |
//! | Euler angles | `rpy` = (roll, pitch, yaw) with R = Rz(yaw) Ry(pitch) Rx(roll); `euler_zyx` = the same rotation, yaw first |
//! | ROS `PoseWithCovariance` | 36 row-major numbers in (x, y, z, rotX, rotY, rotZ); position error in parent axes, rotation error local |
//! | rotation-first sources | GTSAM Pose3, sophus-rs, Lynch & Park, EEME E6911 use [θ; ρ]: convert with an explicit permutation at the boundary |
//! | names | transforms `a_from_b` (`world_from_cam = world_from_body.compose(&body_from_cam)`), points `p_in_a`, covariances `cov_in_body` / `cov_in_world` |
//!
//! **Which way is my covariance?** A covariance Σ attached to a mean μ describes
//! X = μ · Exp(ε), ε ~ N(0, Σ), with ε = [ρ; θ] expressed in the **body** frame of μ, unless
//! it is explicitly marked as left/world. To get the world-frame (left) covariance, use
//! Ad_μ Σ Ad_μᵀ.
//!
//! ```
//! use posecov::lie::{LieGroup, Se3};
//! use nalgebra::{Matrix6, Vector6};
//! let world_from_body = Se3::from_xyz_rpy([1.0, 2.0, 0.0], [0.0, 0.0, 0.5]);
//! let cov_in_body = Matrix6::from_diagonal(&Vector6::new(0.01, 0.04, 0.0, 0.0, 0.0, 0.001));
//! let ad = world_from_body.adj();
//! let cov_in_world = ad * cov_in_body * ad.transpose();
//! // The yaw variance does not depend on the frame; the position block does.
//! assert!((cov_in_world[(5, 5)] - 0.001).abs() < 1e-15);
//! ```
#![deny(missing_docs)]

pub mod app;
pub mod convert;
pub mod draw;
pub mod error;
pub mod eval;
pub mod input;
pub mod interop;
pub mod lie;
pub mod plan;
pub mod propagate;
pub mod sample;
pub mod scene;
pub mod sink;
pub mod uncertain;

#[doc = include_str!("../docs/CONVENTIONS.md")]
pub mod conventions {}

#[doc = include_str!("../docs/REFERENCE_CASES.md")]
pub mod reference_cases {}

pub use error::{Error, Result};
