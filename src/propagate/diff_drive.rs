//! A differential-drive robot with noisy wheels: Long, Wolfe, Mashner & Chirikjian 2012,
//! "The Banana Distribution is Gaussian: A Localization Study with Exponential Coordinates"
//! (RSS 2012), §III–IV.
//!
//! # Model
//! Wheel radius r, wheelbase l, wheel angles driven by dφᵢ = ωᵢ dt + √D dWᵢ (i = 1, 2):
//! dx = (r/2)(dφ₁ + dφ₂) cos θ, dy = (r/2)(dφ₁ + dφ₂) sin θ, dθ = (r/l)(dφ₁ − dφ₂).
//! On SE(2) with the **right** (body) form and tangent [v₁, v₂, α] ([CONVENTIONS §2]):
//! (g⁻¹ ġ)∨ dt = h dt + H dW, h = [(r/2)(ω₁ + ω₂), 0, (r/l)(ω₁ − ω₂)],
//! H = [[r/2, r/2], [0, 0], [r/l, −r/l]]. For constant wheel rates μ(t) = Exp(t h) and, to
//! first order (Long et al. 2012, eq. 19 and the integral after it),
//! Σ(t) = ∫₀ᵗ Ad(μ(τ)⁻¹) D H Hᵀ Ad(μ(τ)⁻¹)ᵀ dτ.
//! (The body-frame error ε(t) obeys dε = −ad(h) ε dt + H dW, so
//! Σ(t) = ∫ Ad(μ(t)⁻¹μ(τ)) D H Hᵀ (…)ᵀ dτ; with constant h, substituting s = t − τ gives the
//! integral above.)
//!
//! # Methods
//! - [`DiffDrive::straight_closed_form`], [`DiffDrive::arc_closed_form`]: Long et al.'s closed
//!   forms (`Method::ClosedForm`);
//! - [`DiffDrive::numeric_integral`]: adaptive Simpson quadrature of the integral for any
//!   constant wheel rates (`Method::NumericIntegral`);
//! - [`DiffDrive::euler_maruyama`]: sample paths of the SDE (seeded, parallel, thread-count
//!   independent), end poses and kept trajectories for drawing.
//!
//! ```
//! use posecov::propagate::diff_drive::DiffDrive;
//! let robot = DiffDrive::try_new(0.033, 0.2, 1.0).unwrap();
//! let closed = robot.straight_closed_form(1.0, 1.0).unwrap();
//! let numeric = robot.numeric_integral(robot.wheel_rates_for(1.0, 0.0), 1.0, 1e-12).unwrap();
//! assert!((closed.pose.cov() - numeric.pose.cov()).amax() < 1e-9);
//! assert!((closed.pose.cov()[(1, 1)] - 0.01815).abs() < 1e-12);
//! ```
//!
//! [CONVENTIONS §2]: crate::conventions#2-tangent-vectors-and-their-order

use nalgebra::{Matrix3, Matrix3x2, Vector2, Vector3};
use rand::Rng;
use rand_distr::StandardNormal;
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::lie::{LieGroup, Se2, Tangent};
use crate::propagate::Propagated;
use crate::sample::{CHUNK_SIZE, chunk_rng};
use crate::uncertain::{Method, Side, UncertainPose};

/// Recursion depth limit of the adaptive Simpson quadrature (2⁴⁰ sub-intervals: never
/// reached by the smooth integrands here; reaching it is reported as non-convergence).
pub const SIMPSON_MAX_DEPTH: usize = 40;

/// A differential-drive robot with wheel noise (Long et al. 2012, §III).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiffDrive {
    wheel_radius: f64,
    wheelbase: f64,
    noise: f64,
}

fn positive(what: &'static str, value: f64, allow_zero: bool) -> Result<f64> {
    let ok = value.is_finite() && (value > 0.0 || (allow_zero && value == 0.0));
    if ok {
        Ok(value)
    } else {
        Err(Error::OutOfRange {
            what,
            value,
            expected: if allow_zero {
                "finite and ≥ 0"
            } else {
                "finite and > 0"
            },
        })
    }
}

impl DiffDrive {
    /// Wheel radius r > 0, wheelbase l > 0 (m), wheel-noise intensity D ≥ 0 (rad²/s).
    /// Errors: [`Error::OutOfRange`] naming the bad parameter.
    ///
    /// ```
    /// use posecov::propagate::diff_drive::DiffDrive;
    /// assert!(DiffDrive::try_new(0.033, 0.2, 1.0).is_ok());
    /// assert!(DiffDrive::try_new(0.033, 0.0, 1.0).is_err());
    /// ```
    pub fn try_new(wheel_radius: f64, wheelbase: f64, noise: f64) -> Result<Self> {
        Ok(Self {
            wheel_radius: positive("wheel radius r", wheel_radius, false)?,
            wheelbase: positive("wheelbase l", wheelbase, false)?,
            noise: positive("wheel noise intensity D", noise, true)?,
        })
    }

    /// Body velocity h = [(r/2)(ω₁ + ω₂), 0, (r/l)(ω₁ − ω₂)] of wheel rates (ω₁, ω₂).
    ///
    /// ```
    /// use posecov::propagate::diff_drive::DiffDrive;
    /// let robot = DiffDrive::try_new(0.5, 1.0, 0.0).unwrap();
    /// assert_eq!(robot.body_velocity([2.0, 2.0]), nalgebra::Vector3::new(1.0, 0.0, 0.0));
    /// ```
    pub fn body_velocity(&self, wheel_rates: [f64; 2]) -> Tangent<3> {
        let (r, l) = (self.wheel_radius, self.wheelbase);
        let [w1, w2] = wheel_rates;
        Vector3::new(0.5 * r * (w1 + w2), 0.0, r / l * (w1 - w2))
    }

    /// Wheel rates (ω₁, ω₂) for forward speed v and yaw rate α̇ (the inverse of
    /// [`body_velocity`](Self::body_velocity)).
    ///
    /// ```
    /// use posecov::propagate::diff_drive::DiffDrive;
    /// let robot = DiffDrive::try_new(0.033, 0.2, 1.0).unwrap();
    /// let h = robot.body_velocity(robot.wheel_rates_for(1.0, 0.5));
    /// assert!((h - nalgebra::Vector3::new(1.0, 0.0, 0.5)).norm() < 1e-14);
    /// ```
    pub fn wheel_rates_for(&self, speed: f64, yaw_rate: f64) -> [f64; 2] {
        let (r, l) = (self.wheel_radius, self.wheelbase);
        let (sum, difference) = (2.0 * speed / r, yaw_rate * l / r);
        [0.5 * (sum + difference), 0.5 * (sum - difference)]
    }

    /// The noise matrix H = [[r/2, r/2], [0, 0], [r/l, −r/l]].
    ///
    /// ```
    /// use posecov::propagate::diff_drive::DiffDrive;
    /// let h = DiffDrive::try_new(0.5, 1.0, 1.0).unwrap().noise_matrix();
    /// assert_eq!(h[(2, 1)], -0.5);
    /// ```
    pub fn noise_matrix(&self) -> Matrix3x2<f64> {
        let (r, l) = (self.wheel_radius, self.wheelbase);
        Matrix3x2::new(0.5 * r, 0.5 * r, 0.0, 0.0, r / l, -r / l)
    }

    /// The nominal pose after time t at constant wheel rates: μ(t) = Exp(t h).
    ///
    /// ```
    /// use posecov::propagate::diff_drive::DiffDrive;
    /// let robot = DiffDrive::try_new(0.033, 0.2, 1.0).unwrap();
    /// let end = robot.nominal(robot.wheel_rates_for(1.0, 0.0), 2.0);
    /// assert!((end.x() - 2.0).abs() < 1e-12);
    /// ```
    pub fn nominal(&self, wheel_rates: [f64; 2], duration: f64) -> Se2 {
        Se2::exp(&(self.body_velocity(wheel_rates) * duration))
    }

    fn result(&self, mean: Se2, cov: Matrix3<f64>, method: Method) -> Propagated<Se2, 3> {
        Propagated {
            pose: UncertainPose::new_unchecked(mean, cov, Side::Right),
            method,
        }
    }

    /// Straight run at speed v for time t (ω₁ = ω₂ = ω = v/r), Long et al. 2012, §IV-A:
    /// Σ₁₁ = D r² t/2, Σ₂₂ = 2Dω²r⁴t³/(3l²), Σ₂₃ = Dωr³t²/l², Σ₃₃ = 2Dr²t/l², Σ₁₂ = Σ₁₃ = 0
    /// (right form, [v₁, v₂, α]). Errors: non-finite v, t < 0.
    ///
    /// ```
    /// use posecov::propagate::diff_drive::DiffDrive;
    /// let s = DiffDrive::try_new(0.033, 0.2, 1.0).unwrap().straight_closed_form(1.0, 1.0).unwrap();
    /// assert!((s.pose.cov()[(0, 0)] - 5.445e-4).abs() < 1e-15);
    /// assert!((s.pose.cov()[(1, 2)] - 0.027225).abs() < 1e-12);
    /// ```
    pub fn straight_closed_form(&self, speed: f64, duration: f64) -> Result<Propagated<Se2, 3>> {
        check_motion(speed, 0.0, duration)?;
        let (r, l, d, t) = (self.wheel_radius, self.wheelbase, self.noise, duration);
        let w = speed / r;
        let mut cov = Matrix3::zeros();
        cov[(0, 0)] = d * r * r * t / 2.0;
        cov[(1, 1)] = 2.0 * d * w * w * r.powi(4) * t.powi(3) / (3.0 * l * l);
        cov[(1, 2)] = d * w * r.powi(3) * t * t / (l * l);
        cov[(2, 1)] = cov[(1, 2)];
        cov[(2, 2)] = 2.0 * d * r * r * t / (l * l);
        let mean = Se2::from_xy_theta(speed * t, 0.0, 0.0);
        Ok(self.result(mean, cov, Method::ClosedForm))
    }

    /// Constant-curvature arc at speed v and yaw rate α̇ ≠ 0 for time t, radius a = v/α̇
    /// (signed, so right turns and reversing work), Long et al. 2012, §IV-B, with
    /// c = D r²/(α̇ l²) and φ = α̇t:
    /// Σ₁₁ = c[(4a² + l²)(2φ + sin 2φ) + 16a²(φ − 2 sin φ)]/8,
    /// Σ₁₂ = −(c/2)(4a²(cos φ − 1) + l²(1 + cos φ)) sin²(φ/2), Σ₁₃ = 2ca(φ − sin φ),
    /// Σ₂₂ = −c(4a² + l²)(−2φ + sin 2φ)/8, Σ₂₃ = −2ca(cos φ − 1), Σ₃₃ = 2cα̇t.
    ///
    /// Σ₁₂ and Σ₃₃ are integrated here from the integrand (with
    /// Ad(μ(τ)⁻¹) = [[cos ψ, sin ψ, a(1 − cos ψ)], [−sin ψ, cos ψ, a sin ψ], [0, 0, 1]], ψ = α̇τ):
    /// the forms quoted as "−(c/2)(4a²(cos φ − 1) + l²) sin²(φ/2)" and "2cα̇" agree with them
    /// only at φ = π/2 and t = 1 (the quarter circle in 1 s of the paper's example); the
    /// numeric integral confirms the general forms.
    ///
    /// Errors: α̇ = 0 (use [`straight_closed_form`](Self::straight_closed_form)), non-finite
    /// inputs, t < 0.
    ///
    /// ```
    /// use posecov::propagate::diff_drive::DiffDrive;
    /// use std::f64::consts::FRAC_PI_2;
    /// let robot = DiffDrive::try_new(0.033, 0.2, 1.0).unwrap();
    /// let arc = robot.arc_closed_form(FRAC_PI_2, FRAC_PI_2, 1.0).unwrap(); // quarter circle, a = 1
    /// assert!((arc.pose.cov()[(0, 2)] - 0.019786).abs() < 1e-6);
    /// assert!(robot.arc_closed_form(1.0, 0.0, 1.0).is_err());
    /// ```
    pub fn arc_closed_form(
        &self,
        speed: f64,
        yaw_rate: f64,
        duration: f64,
    ) -> Result<Propagated<Se2, 3>> {
        check_motion(speed, yaw_rate, duration)?;
        if yaw_rate == 0.0 {
            return Err(Error::OutOfRange {
                what: "arc yaw rate α̇",
                value: yaw_rate,
                expected: "α̇ ≠ 0 (a straight run has its own closed form)",
            });
        }
        let (r, l, d, t) = (self.wheel_radius, self.wheelbase, self.noise, duration);
        let (a, rate) = (speed / yaw_rate, yaw_rate);
        let c = d * r * r / (rate * l * l);
        let (phi, a2, l2) = (rate * t, a * a, l * l);
        let mut cov = Matrix3::zeros();
        cov[(0, 0)] = c
            * ((4.0 * a2 + l2) * (2.0 * phi + (2.0 * phi).sin())
                + 16.0 * a2 * (phi - 2.0 * phi.sin()))
            / 8.0;
        cov[(0, 1)] = -(c / 2.0)
            * (4.0 * a2 * (phi.cos() - 1.0) + l2 * (1.0 + phi.cos()))
            * (phi / 2.0).sin().powi(2);
        cov[(0, 2)] = 2.0 * c * a * (phi - phi.sin());
        cov[(1, 1)] = -c * (4.0 * a2 + l2) * (-2.0 * phi + (2.0 * phi).sin()) / 8.0;
        cov[(1, 2)] = -2.0 * c * a * (phi.cos() - 1.0);
        cov[(2, 2)] = 2.0 * c * rate * t;
        let cov = Matrix3::from_fn(|i, j| if i <= j { cov[(i, j)] } else { cov[(j, i)] });
        let mean = Se2::exp(&(Vector3::new(speed, 0.0, yaw_rate) * t));
        Ok(self.result(mean, cov, Method::ClosedForm))
    }

    /// The first-order covariance for constant wheel rates by adaptive Simpson quadrature of
    /// Σ(t) = ∫₀ᵗ Ad(μ(τ)⁻¹) D H Hᵀ Ad(μ(τ)⁻¹)ᵀ dτ, μ(τ) = Exp(τ h) (Long et al. 2012, §III),
    /// to an absolute tolerance `tolerance` on every entry (Lyness' criterion |S₂ − S₁| ≤ 15 ε
    /// with Richardson correction). Errors: bad inputs, `tolerance` ≤ 0, no convergence within
    /// [`SIMPSON_MAX_DEPTH`] halvings ([`Error::NotConverged`]).
    ///
    /// ```
    /// use posecov::propagate::diff_drive::DiffDrive;
    /// use std::f64::consts::FRAC_PI_2;
    /// let robot = DiffDrive::try_new(0.033, 0.2, 1.0).unwrap();
    /// let rates = robot.wheel_rates_for(FRAC_PI_2, FRAC_PI_2);
    /// let n = robot.numeric_integral(rates, 1.0, 1e-12).unwrap();
    /// let c = robot.arc_closed_form(FRAC_PI_2, FRAC_PI_2, 1.0).unwrap();
    /// assert!((n.pose.cov() - c.pose.cov()).amax() < 1e-9);
    /// ```
    pub fn numeric_integral(
        &self,
        wheel_rates: [f64; 2],
        duration: f64,
        tolerance: f64,
    ) -> Result<Propagated<Se2, 3>> {
        check_motion(wheel_rates[0], wheel_rates[1], duration)?;
        positive("quadrature tolerance", tolerance, false)?;
        let h = self.body_velocity(wheel_rates);
        let noise = self.noise_matrix();
        let diffusion = noise * noise.transpose() * self.noise;
        let integrand = |tau: f64| {
            let ad = Se2::exp(&(-h * tau)).adj();
            ad * diffusion * ad.transpose()
        };
        let cov = adaptive_simpson(&integrand, 0.0, duration, tolerance)?;
        let cov = (cov + cov.transpose()) * 0.5;
        Ok(self.result(
            self.nominal(wheel_rates, duration),
            cov,
            Method::NumericIntegral,
        ))
    }

    /// Euler–Maruyama sample paths of the wheel SDE from the identity pose for time t at
    /// constant wheel rates: per step dφᵢ = ωᵢ δt + √(D δt) zᵢ, zᵢ ~ N(0, 1), then
    /// x += (r/2)(dφ₁ + dφ₂) cos θ, y += (r/2)(dφ₁ + dφ₂) sin θ, θ += (r/l)(dφ₁ − dφ₂) (Itô;
    /// here equal to Stratonovich, the noise of x, y does not depend on θ's noise direction).
    /// The step count is ⌈t/dt⌉ and δt = t / steps. Paths are seeded per chunk with
    /// [`chunk_rng`]`(seed, 0, chunk)`: identical whatever the thread count.
    ///
    /// Errors: [`Error::OutOfRange`] for dt ∉ (0, t], t ≤ 0, fewer than 2 samples.
    ///
    /// ```
    /// use posecov::propagate::diff_drive::{DiffDrive, EulerMaruyama};
    /// let robot = DiffDrive::try_new(0.033, 0.2, 1.0).unwrap();
    /// let em = EulerMaruyama::new(0.01, 100, 1).with_trajectories(2, 10);
    /// let s = robot.euler_maruyama(robot.wheel_rates_for(1.0, 0.0), 1.0, &em).unwrap();
    /// assert_eq!((s.end_poses.len(), s.trajectories.len(), s.trajectories[0].len()), (100, 2, 11));
    /// assert!(robot.euler_maruyama([1.0, 1.0], 1.0, &EulerMaruyama::new(0.0, 100, 1)).is_err());
    /// ```
    pub fn euler_maruyama(
        &self,
        wheel_rates: [f64; 2],
        duration: f64,
        settings: &EulerMaruyama,
    ) -> Result<SdeSamples> {
        check_motion(wheel_rates[0], wheel_rates[1], duration)?;
        let steps = settings.validate(duration)?;
        let dt = duration / steps as f64;
        let path = PathSimulator {
            robot: *self,
            wheel_rates,
            dt,
            steps,
            stride: settings.trajectory_stride.max(1),
        };
        let mut end_poses = vec![Se2::identity(); settings.samples];
        let kept: Vec<Vec<Vec<Se2>>> = end_poses
            .par_chunks_mut(CHUNK_SIZE)
            .enumerate()
            .map(|(c, chunk)| {
                let c = settings.first_chunk as usize + c;
                let mut rng = chunk_rng(settings.seed, 0, c as u64);
                let mut trajectories = Vec::new();
                for (i, end) in chunk.iter_mut().enumerate() {
                    let keep = c * CHUNK_SIZE + i < settings.trajectories;
                    let mut trajectory = keep.then(|| Vec::with_capacity(steps / path.stride + 2));
                    *end = path.run(&mut rng, trajectory.as_mut());
                    trajectories.extend(trajectory);
                }
                trajectories
            })
            .collect();
        Ok(SdeSamples {
            end_poses,
            trajectories: kept.into_iter().flatten().collect(),
            dt,
            steps,
        })
    }
}

fn check_motion(a: f64, b: f64, duration: f64) -> Result<()> {
    crate::error::check_finite("motion (speed / rates)", [a, b])?;
    positive("duration t", duration, true).map(|_| ())
}

/// One Euler–Maruyama path with fixed settings.
struct PathSimulator {
    robot: DiffDrive,
    wheel_rates: [f64; 2],
    dt: f64,
    steps: usize,
    stride: usize,
}

impl PathSimulator {
    fn run<R: Rng>(&self, rng: &mut R, mut trajectory: Option<&mut Vec<Se2>>) -> Se2 {
        let (r, l) = (self.robot.wheel_radius, self.robot.wheelbase);
        let sd = (self.robot.noise * self.dt).sqrt();
        let [w1, w2] = self.wheel_rates;
        let (mut x, mut y, mut theta) = (0.0f64, 0.0f64, 0.0f64);
        for k in 0..self.steps {
            if let Some(t) = trajectory.as_deref_mut()
                && k % self.stride == 0
            {
                t.push(Se2::from_xy_theta(x, y, theta));
            }
            let z1: f64 = rng.sample(StandardNormal);
            let z2: f64 = rng.sample(StandardNormal);
            let (d1, d2) = (w1 * self.dt + sd * z1, w2 * self.dt + sd * z2);
            let forward = 0.5 * r * (d1 + d2);
            x += forward * theta.cos();
            y += forward * theta.sin();
            theta += r / l * (d1 - d2);
        }
        let end = Se2::from_xy_theta(x, y, theta);
        if let Some(t) = trajectory {
            t.push(end);
        }
        end
    }
}

/// Euler–Maruyama settings: time step, sample count, seed, and how many trajectories to keep
/// (the first `trajectories` paths, every `trajectory_stride`-th step plus the end).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EulerMaruyama {
    /// Requested time step dt (the actual δt = t / ⌈t/dt⌉).
    pub dt: f64,
    /// Number of sample paths (≥ 2).
    pub samples: usize,
    /// Seed.
    pub seed: u64,
    /// Paths kept for drawing (default 0).
    pub trajectories: usize,
    /// Keep every this-many steps of a kept path (default 1).
    pub trajectory_stride: usize,
    /// Chunk index of the first path (default 0): path `i` of this run is path
    /// `first_chunk · CHUNK_SIZE + i` of the whole sample, with that path's random stream, so a
    /// large sample can be simulated block by block.
    pub first_chunk: u64,
}

impl EulerMaruyama {
    /// `samples` paths with step `dt` from `seed`, no trajectories kept.
    ///
    /// ```
    /// use posecov::propagate::diff_drive::EulerMaruyama;
    /// assert_eq!(EulerMaruyama::new(1e-3, 10, 0).trajectories, 0);
    /// ```
    pub fn new(dt: f64, samples: usize, seed: u64) -> Self {
        Self {
            dt,
            samples,
            seed,
            trajectories: 0,
            trajectory_stride: 1,
            first_chunk: 0,
        }
    }

    /// Simulates the block of a larger sample that starts at chunk `first_chunk` (kept
    /// trajectories count from the whole sample's first path).
    ///
    /// ```
    /// use posecov::propagate::diff_drive::{DiffDrive, EulerMaruyama};
    /// use posecov::sample::CHUNK_SIZE;
    /// let robot = DiffDrive::try_new(0.033, 0.2, 1.0).unwrap();
    /// let rates = robot.wheel_rates_for(1.0, 0.5);
    /// let whole = robot.euler_maruyama(rates, 0.1, &EulerMaruyama::new(0.01, 2 * CHUNK_SIZE, 3)).unwrap();
    /// let tail = EulerMaruyama::new(0.01, CHUNK_SIZE, 3).starting_at_chunk(1);
    /// let tail = robot.euler_maruyama(rates, 0.1, &tail).unwrap();
    /// assert_eq!(&whole.end_poses[CHUNK_SIZE..], &tail.end_poses[..]);
    /// ```
    pub fn starting_at_chunk(self, first_chunk: u64) -> Self {
        Self {
            first_chunk,
            ..self
        }
    }

    /// Keeps the first `count` paths, every `stride`-th step (and the end pose).
    ///
    /// ```
    /// use posecov::propagate::diff_drive::EulerMaruyama;
    /// assert_eq!(EulerMaruyama::new(1e-3, 10, 0).with_trajectories(3, 20).trajectory_stride, 20);
    /// ```
    pub fn with_trajectories(self, count: usize, stride: usize) -> Self {
        Self {
            trajectories: count,
            trajectory_stride: stride,
            ..self
        }
    }

    /// Checks the settings for a run of length `duration` and returns the step count.
    fn validate(&self, duration: f64) -> Result<usize> {
        if !(self.dt.is_finite() && self.dt > 0.0 && self.dt <= duration) {
            return Err(Error::OutOfRange {
                what: "Euler–Maruyama time step dt",
                value: self.dt,
                expected: "finite, 0 < dt ≤ t (and t > 0)",
            });
        }
        if self.samples < 2 {
            return Err(Error::OutOfRange {
                what: "Euler–Maruyama sample count",
                value: self.samples as f64,
                expected: "at least 2 paths",
            });
        }
        let steps = (duration / self.dt - 1e-9).ceil().max(1.0);
        if steps > 1e9 {
            return Err(Error::OutOfRange {
                what: "Euler–Maruyama step count t/dt",
                value: steps,
                expected: "at most 1e9 steps",
            });
        }
        Ok(steps as usize)
    }
}

/// Sample paths of the wheel SDE.
#[derive(Clone, Debug, PartialEq)]
pub struct SdeSamples {
    /// End pose of every path.
    pub end_poses: Vec<Se2>,
    /// The kept paths, each from the identity to its end pose.
    pub trajectories: Vec<Vec<Se2>>,
    /// The time step used.
    pub dt: f64,
    /// The number of steps per path.
    pub steps: usize,
}

/// The Cartesian mean (x̄, ȳ) of the positions of poses: the point that falls *inside* the
/// banana while the Lie mean stays on the nominal end point (Long et al. 2012, §V).
/// Errors: [`Error::TooFewSamples`] for no poses.
///
/// ```
/// use posecov::lie::Se2;
/// use posecov::propagate::diff_drive::cartesian_mean_position;
/// let m = cartesian_mean_position(&[Se2::from_xy_theta(1.0, 0.0, 0.0), Se2::from_xy_theta(0.0, 1.0, 1.0)]).unwrap();
/// assert_eq!(m, nalgebra::Vector2::new(0.5, 0.5));
/// ```
pub fn cartesian_mean_position(poses: &[Se2]) -> Result<Vector2<f64>> {
    if poses.is_empty() {
        return Err(Error::TooFewSamples {
            what: "Cartesian mean position",
            needed: 1,
            got: 0,
        });
    }
    let sum: Vector2<f64> = poses.iter().map(|p| *p.translation()).sum();
    Ok(sum / poses.len() as f64)
}

/// ∫ₐᵇ f by adaptive Simpson quadrature to absolute tolerance `tolerance` (max entry).
fn adaptive_simpson<F: Fn(f64) -> Matrix3<f64>>(
    f: &F,
    a: f64,
    b: f64,
    tolerance: f64,
) -> Result<Matrix3<f64>> {
    let (fa, fm, fb) = (f(a), f(0.5 * (a + b)), f(b));
    let whole = (fa + fm * 4.0 + fb) * ((b - a) / 6.0);
    simpson_step(f, [a, b], [fa, fm, fb], whole, tolerance, SIMPSON_MAX_DEPTH)
}

fn simpson_step<F: Fn(f64) -> Matrix3<f64>>(
    f: &F,
    [a, b]: [f64; 2],
    [fa, fm, fb]: [Matrix3<f64>; 3],
    whole: Matrix3<f64>,
    tolerance: f64,
    depth: usize,
) -> Result<Matrix3<f64>> {
    let m = 0.5 * (a + b);
    let (flm, frm) = (f(0.5 * (a + m)), f(0.5 * (m + b)));
    let left = (fa + flm * 4.0 + fm) * ((m - a) / 6.0);
    let right = (fm + frm * 4.0 + fb) * ((b - m) / 6.0);
    let delta = left + right - whole;
    let error = delta.amax();
    if error <= 15.0 * tolerance {
        return Ok(left + right + delta / 15.0);
    }
    if depth == 0 || !error.is_finite() {
        return Err(Error::NotConverged {
            what: "adaptive Simpson quadrature",
            iterations: SIMPSON_MAX_DEPTH,
            last_step: error,
            tolerance,
            last_estimate: format!("{:?}", left + right),
        });
    }
    Ok(
        simpson_step(f, [a, m], [fa, flm, fm], left, tolerance / 2.0, depth - 1)?
            + simpson_step(f, [m, b], [fm, frm, fb], right, tolerance / 2.0, depth - 1)?,
    )
}
