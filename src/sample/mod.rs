//! Sampling uncertain poses and the statistics of sample sets ([CONVENTIONS §8]).
//!
//! # Drawing
//! A [`Sampler`] holds μ, a square root L of Σ (L Lᵀ = Σ) and the side; a draw is
//! z ~ N(0, I), ε = L z, then X = μ · Exp(ε) (right / body) or X = Exp(ε) · μ (left / world).
//! L is the Cholesky factor when Σ is positive definite, else the eigen-based square root
//! L = V diag(√max(λ, 0)) (for PSD-singular Σ such as a pose with no z / roll / pitch noise).
//!
//! # Seeding scheme (identical results whatever the thread count)
//! Parallel draws split the output into fixed chunks of [`CHUNK_SIZE`] samples. Chunk `c` of
//! the random *family* `f` (one family per independent source of randomness of an operation,
//! e.g. the initial pose and each odometry step) draws from
//! `ChaCha8Rng::seed_from_u64(seed + f · 0x9E37_79B9_7F4A_7C15)` with `set_stream(c)`:
//! [`chunk_rng`]. Which thread runs a chunk never changes what the chunk draws, and sums
//! over samples are formed per chunk and then added in chunk order, so every result is
//! bit-identical for a given seed on 1 or 64 threads.
//!
//! # Statistics
//! - [`lie_mean`]: μ ← μ · Exp(mean Log(μ⁻¹ Xᵢ)) (right; left: μ ← Exp(mean Log(Xᵢ μ⁻¹)) · μ)
//!   until ‖step‖ < [`LIE_MEAN_TOLERANCE`], at most [`LIE_MEAN_MAX_ITERATIONS`] iterations; on
//!   no convergence a [`MeanError::NotConverged`] carrying the last estimate.
//! - [`centred_covariance`]: 1/(N−1) Σ ξᵢ ξᵢᵀ about the sample Lie mean (ROB 530).
//! - [`uncentred_covariance`]: 1/N Σ ξᵢ ξᵢᵀ about a given mean, E\[ξξᵀ\] (Barfoot & Furgale
//!   2014, §IV experiments).
//! - [`nees`]: normalised estimation error squared of samples against a claimed covariance.
//!
//! ```
//! use posecov::lie::{LieGroup, Se2};
//! use posecov::sample::{Sampler, sample_statistics};
//! use posecov::uncertain::{Side, UncertainPose};
//! let pose = UncertainPose::try_from_std_devs(Se2::from_xy_theta(1.0, 2.0, 0.3), [0.1, 0.05, 0.02], Side::Right).unwrap();
//! let samples = Sampler::new(&pose).unwrap().draw_par(20_000, 7);
//! let stats = sample_statistics(&samples, Side::Right).unwrap();
//! assert!(stats.mean.is_approx(pose.mean(), 0.01));
//! assert!((stats.cov[(0, 0)] / 0.01 - 1.0).abs() < 0.05);
//! ```
//!
//! [CONVENTIONS §8]: crate::conventions#8-sample-statistics
//!
//! # What this folder owns
//!
//! Seeded chunked sampling (`mod.rs`); the one Lie mean (`LieMeanAccumulator`, streaming over
//! blocks) and sample statistics (`statistics.rs`).

use std::fmt::Debug;

use nalgebra::{Cholesky, DMatrix, SymmetricEigen};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use rayon::prelude::*;

use crate::error::{Result, check_finite};
use crate::lie::{LieGroup, Tangent, TangentMatrix};
use crate::uncertain::{Side, UncertainPose};

/// Samples per parallel chunk: the unit of work and of random streams (see the
/// [seeding scheme](self#seeding-scheme-identical-results-whatever-the-thread-count)).
pub const CHUNK_SIZE: usize = 1024;

/// The Lie mean stops when the norm of its last tangent update is below this ([CONVENTIONS §8]).
///
/// [CONVENTIONS §8]: crate::conventions#8-sample-statistics
pub const LIE_MEAN_TOLERANCE: f64 = 1e-10;

/// The Lie mean gives up after this many iterations ([CONVENTIONS §8]).
///
/// [CONVENTIONS §8]: crate::conventions#8-sample-statistics
pub const LIE_MEAN_MAX_ITERATIONS: usize = 100;

/// Golden-ratio increment that separates the seeds of random families.
const FAMILY_INCREMENT: u64 = 0x9E37_79B9_7F4A_7C15;

/// The random generator of chunk `chunk` of random family `family`:
/// `ChaCha8Rng::seed_from_u64(seed + family · 0x9E37_79B9_7F4A_7C15)` with `set_stream(chunk)`
/// (wrapping arithmetic). Independent of threads by construction.
///
/// ```
/// use posecov::sample::chunk_rng;
/// use rand::Rng;
/// let a: u64 = chunk_rng(1, 0, 3).random();
/// let b: u64 = chunk_rng(1, 0, 3).random();
/// let c: u64 = chunk_rng(1, 0, 4).random();
/// assert_eq!(a, b);
/// assert_ne!(a, c);
/// ```
pub fn chunk_rng(seed: u64, family: u64, chunk: u64) -> ChaCha8Rng {
    let mut rng =
        ChaCha8Rng::seed_from_u64(seed.wrapping_add(family.wrapping_mul(FAMILY_INCREMENT)));
    rng.set_stream(chunk);
    rng
}

/// Fills `out` in parallel, chunk by chunk: chunk `c` calls `fill(rng, chunk)` with
/// [`chunk_rng`]`(seed, family, c)`. The per-sample work inside `fill` should not allocate.
///
/// ```
/// use posecov::sample::fill_par;
/// use rand::Rng;
/// let mut v = vec![0.0; 3000];
/// fill_par(&mut v, 5, 0, |rng, chunk| chunk.iter_mut().for_each(|x| *x = rng.random::<f64>()));
/// assert!(v.iter().all(|x| (0.0..1.0).contains(x)));
/// ```
pub fn fill_par<T, F>(out: &mut [T], seed: u64, family: u64, fill: F)
where
    T: Send,
    F: Fn(&mut ChaCha8Rng, &mut [T]) + Sync,
{
    fill_par_from(out, seed, family, 0, fill);
}

/// [`fill_par`] for a block of a larger sample: `out[0]` is sample `first_chunk · CHUNK_SIZE`
/// of the whole, so chunk `c` of `out` uses [`chunk_rng`]`(seed, family, first_chunk + c)`.
/// Filling a sample block by block therefore gives exactly the draws of one `fill_par` over
/// all of it (what lets a 10⁷-sample Monte Carlo run in bounded memory).
///
/// ```
/// use posecov::sample::{CHUNK_SIZE, fill_par, fill_par_from};
/// use rand::Rng;
/// let draw = |rng: &mut rand_chacha::ChaCha8Rng, c: &mut [f64]| c.iter_mut().for_each(|x| *x = rng.random());
/// let mut whole = vec![0.0; 3 * CHUNK_SIZE];
/// fill_par(&mut whole, 7, 1, draw);
/// let mut tail = vec![0.0; 2 * CHUNK_SIZE];
/// fill_par_from(&mut tail, 7, 1, 1, draw);
/// assert_eq!(&whole[CHUNK_SIZE..], &tail[..]);
/// ```
pub fn fill_par_from<T, F>(out: &mut [T], seed: u64, family: u64, first_chunk: u64, fill: F)
where
    T: Send,
    F: Fn(&mut ChaCha8Rng, &mut [T]) + Sync,
{
    out.par_chunks_mut(CHUNK_SIZE)
        .enumerate()
        .for_each(|(c, chunk)| fill(&mut chunk_rng(seed, family, first_chunk + c as u64), chunk));
}

/// A standard normal vector z ~ N(0, I) in ℝᴺ.
///
/// ```
/// use posecov::sample::standard_normal;
/// let z = standard_normal::<3, _>(&mut posecov::sample::chunk_rng(0, 0, 0));
/// assert!(z.iter().all(|v| v.is_finite()));
/// ```
#[inline]
pub fn standard_normal<const N: usize, R: Rng + ?Sized>(rng: &mut R) -> Tangent<N> {
    Tangent::<N>::from_fn(|_, _| rng.sample(StandardNormal))
}

/// A square root L of a covariance, L Lᵀ = Σ: the lower Cholesky factor when Σ is positive
/// definite, else V diag(√max(λ, 0)) from the eigen-decomposition Σ = V diag(λ) Vᵀ (PSD-singular
/// Σ, e.g. zero rows). Errors: [`Error::NonFinite`](crate::Error::NonFinite) for NaN / ±∞.
///
/// ```
/// use posecov::sample::covariance_square_root;
/// use nalgebra::Matrix3;
/// let cov = Matrix3::from_diagonal(&nalgebra::Vector3::new(0.0, 4.0, 0.0)); // singular
/// let l = covariance_square_root(&cov).unwrap();
/// assert!((l * l.transpose() - cov).norm() < 1e-14);
/// ```
pub fn covariance_square_root<const N: usize>(cov: &TangentMatrix<N>) -> Result<TangentMatrix<N>> {
    check_finite("covariance", cov.transpose().iter().copied())?;
    let sym = (cov + cov.transpose()) * 0.5;
    if let Some(chol) = Cholesky::new(sym) {
        return Ok(chol.l());
    }
    // Dynamic storage: the static-size eigensolver needs bounds a const-generic N lacks.
    let eigen = SymmetricEigen::new(DMatrix::from_iterator(N, N, sym.iter().copied()));
    let roots = eigen.eigenvalues.map(|l| l.max(0.0).sqrt());
    let root = &eigen.eigenvectors * DMatrix::from_diagonal(&roots);
    Ok(TangentMatrix::<N>::from_iterator(root.iter().copied()))
}

/// A square root S Sᵀ = Σ of a PSD covariance of any size (e.g. the 2N × 2N joint covariance
/// of a correlated pair): S = V diag(√max(λ, 0)) from Σ = V diag(λ) Vᵀ, tolerating zero rows;
/// S's columns are Σ's principal axes scaled by their standard deviations.
///
/// ```
/// use posecov::sample::joint_square_root;
/// use nalgebra::DMatrix;
/// let joint = DMatrix::from_row_slice(2, 2, &[1.0, 0.9, 0.9, 1.0]);
/// let s = joint_square_root(&joint);
/// assert!((&s * s.transpose() - joint).norm() < 1e-14);
/// ```
pub fn joint_square_root(cov: &DMatrix<f64>) -> DMatrix<f64> {
    let eig = SymmetricEigen::new(cov.clone());
    let sqrt = DMatrix::from_diagonal(&eig.eigenvalues.map(|l| l.max(0.0).sqrt()));
    &eig.eigenvectors * sqrt
}

/// The tangent ξ of `x` about `mean` on `side`: right ξ = Log(μ⁻¹ x), left ξ = Log(x μ⁻¹).
///
/// ```
/// use posecov::lie::{LieGroup, So2};
/// use posecov::sample::tangent_about;
/// use posecov::uncertain::Side;
/// let xi = tangent_about(&So2::from_angle(0.5), &So2::from_angle(0.2), Side::Right);
/// assert!((xi[0] - 0.3).abs() < 1e-15);
/// ```
pub fn tangent_about<G: LieGroup<N>, const N: usize>(x: &G, mean: &G, side: Side) -> Tangent<N> {
    match side {
        Side::Right => x.rminus(mean),
        Side::Left => x.lminus(mean),
    }
}

/// Moves `mean` by the tangent `step` on `side`: right μ · Exp(step), left Exp(step) · μ.
///
/// ```
/// use posecov::lie::{LieGroup, So2};
/// use posecov::sample::retract;
/// use posecov::uncertain::Side;
/// assert!((retract(&So2::from_angle(0.2), &nalgebra::Vector1::new(0.3), Side::Left).angle() - 0.5).abs() < 1e-15);
/// ```
#[inline]
pub fn retract<G: LieGroup<N>, const N: usize>(mean: &G, step: &Tangent<N>, side: Side) -> G {
    match side {
        Side::Right => mean.rplus(step),
        Side::Left => mean.lplus(step),
    }
}

// --------------------------------------------------------------------------------------------
// Drawing.

/// Draws poses from an [`UncertainPose`]: X = μ · Exp(L z) (right) or Exp(L z) · μ (left),
/// z ~ N(0, I), L Lᵀ = Σ ([`covariance_square_root`]).
///
/// ```
/// use posecov::lie::{LieGroup, Se3};
/// use posecov::sample::Sampler;
/// use posecov::uncertain::UncertainPose;
/// use rand::SeedableRng;
/// let sampler = Sampler::new(&UncertainPose::certain(Se3::identity())).unwrap();
/// let x = sampler.draw(&mut rand_chacha::ChaCha8Rng::seed_from_u64(1));
/// assert_eq!(x, Se3::identity().compose(&Se3::exp(&nalgebra::Vector6::zeros())));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sampler<G: LieGroup<N>, const N: usize> {
    mean: G,
    factor: TangentMatrix<N>,
    side: Side,
}

impl<G: LieGroup<N>, const N: usize> Sampler<G, N> {
    /// A sampler for `pose`. Errors: a non-finite covariance.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So3};
    /// use posecov::sample::Sampler;
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(So3::identity(), [0.1, 0.2, 0.3], Side::Left).unwrap();
    /// let s = Sampler::new(&p).unwrap();
    /// assert!((s.factor()[(2, 2)] - 0.3).abs() < 1e-15);
    /// ```
    pub fn new(pose: &UncertainPose<G, N>) -> Result<Self> {
        Ok(Self {
            mean: *pose.mean(),
            factor: covariance_square_root(pose.cov())?,
            side: pose.side(),
        })
    }

    /// One sampler of identity · Exp(w), w ~ N(0, Σ_k), per covariance (the noise of each
    /// step of a propagation). Errors: a non-finite covariance.
    ///
    /// ```
    /// use posecov::lie::So2;
    /// use posecov::sample::Sampler;
    /// let s = Sampler::<So2, 1>::right_noise(&[nalgebra::Matrix1::new(4.0)]).unwrap();
    /// assert_eq!(s[0].factor()[(0, 0)], 2.0);
    /// ```
    pub fn right_noise(covariances: &[TangentMatrix<N>]) -> Result<Vec<Self>> {
        covariances
            .iter()
            .map(|c| {
                Self::new(&UncertainPose::new_unchecked(
                    G::identity(),
                    *c,
                    Side::Right,
                ))
            })
            .collect()
    }

    /// The square root L (L Lᵀ = Σ) the sampler uses.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::sample::Sampler;
    /// use posecov::uncertain::UncertainPose;
    /// let s = Sampler::new(&UncertainPose::certain(So2::identity())).unwrap();
    /// assert_eq!(s.factor()[(0, 0)], 0.0);
    /// ```
    pub fn factor(&self) -> &TangentMatrix<N> {
        &self.factor
    }

    /// One tangent perturbation ε = L z, z ~ N(0, I).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::sample::{Sampler, chunk_rng};
    /// use posecov::uncertain::UncertainPose;
    /// let s = Sampler::new(&UncertainPose::certain(So2::identity())).unwrap();
    /// assert_eq!(s.draw_tangent(&mut chunk_rng(0, 0, 0))[0], 0.0);
    /// ```
    #[inline]
    pub fn draw_tangent<R: Rng + ?Sized>(&self, rng: &mut R) -> Tangent<N> {
        self.factor * standard_normal::<N, R>(rng)
    }

    /// The pose at perturbation ε: μ · Exp(ε) (right) or Exp(ε) · μ (left).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::sample::Sampler;
    /// use posecov::uncertain::UncertainPose;
    /// let s = Sampler::new(&UncertainPose::certain(So2::from_angle(0.1))).unwrap();
    /// assert!((s.perturb(&nalgebra::Vector1::new(0.2)).angle() - 0.3).abs() < 1e-15);
    /// ```
    #[inline]
    pub fn perturb(&self, eps: &Tangent<N>) -> G {
        retract(&self.mean, eps, self.side)
    }

    /// One pose drawn with the caller's generator.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::sample::{Sampler, chunk_rng};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(Se2::identity(), [0.1, 0.1, 0.1], Side::Right).unwrap();
    /// let x = Sampler::new(&p).unwrap().draw(&mut chunk_rng(3, 0, 0));
    /// assert!(x.rminus(&Se2::identity()).norm() < 1.0);
    /// ```
    #[inline]
    pub fn draw<R: Rng + ?Sized>(&self, rng: &mut R) -> G {
        self.perturb(&self.draw_tangent(rng))
    }

    /// `n` poses drawn sequentially with the caller's generator.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So3};
    /// use posecov::sample::{Sampler, chunk_rng};
    /// use posecov::uncertain::UncertainPose;
    /// let s = Sampler::new(&UncertainPose::certain(So3::identity())).unwrap();
    /// assert_eq!(s.draw_many(&mut chunk_rng(0, 0, 0), 5).len(), 5);
    /// ```
    pub fn draw_many<R: Rng + ?Sized>(&self, rng: &mut R, n: usize) -> Vec<G> {
        (0..n).map(|_| self.draw(rng)).collect()
    }

    /// `n` poses drawn in parallel (rayon), identical for a given `seed` whatever the thread
    /// count: random family 0 of the [seeding scheme](self#seeding-scheme-identical-results-whatever-the-thread-count).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, Se2};
    /// use posecov::sample::Sampler;
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(Se2::identity(), [0.1, 0.1, 0.1], Side::Right).unwrap();
    /// let s = Sampler::new(&p).unwrap();
    /// assert_eq!(s.draw_par(3000, 42), s.draw_par(3000, 42));
    /// ```
    pub fn draw_par(&self, n: usize, seed: u64) -> Vec<G> {
        let mut out = vec![self.mean; n];
        self.fill_par(&mut out, seed, 0);
        out
    }

    /// Overwrites `out` with draws in parallel from random family `family` (see
    /// [`draw_par`](Self::draw_par)); no allocation per sample.
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::sample::Sampler;
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let p = UncertainPose::try_from_std_devs(So2::identity(), [0.1], Side::Right).unwrap();
    /// let mut out = vec![So2::identity(); 10];
    /// Sampler::new(&p).unwrap().fill_par(&mut out, 1, 0);
    /// assert!(out.iter().any(|x| x.angle() != 0.0));
    /// ```
    pub fn fill_par(&self, out: &mut [G], seed: u64, family: u64) {
        self.fill_par_from(out, seed, family, 0);
    }

    /// [`fill_par`](Self::fill_par) for the block of a larger sample that starts at chunk
    /// `first_chunk` (see [`fill_par_from`]).
    ///
    /// ```
    /// use posecov::lie::{LieGroup, So2};
    /// use posecov::sample::{CHUNK_SIZE, Sampler};
    /// use posecov::uncertain::{Side, UncertainPose};
    /// let s = Sampler::new(&UncertainPose::try_from_std_devs(So2::identity(), [0.1], Side::Right).unwrap()).unwrap();
    /// let mut whole = vec![So2::identity(); 2 * CHUNK_SIZE];
    /// s.fill_par(&mut whole, 3, 0);
    /// let mut second = vec![So2::identity(); CHUNK_SIZE];
    /// s.fill_par_from(&mut second, 3, 0, 1);
    /// assert_eq!(&whole[CHUNK_SIZE..], &second[..]);
    /// ```
    pub fn fill_par_from(&self, out: &mut [G], seed: u64, family: u64, first_chunk: u64) {
        fill_par_from(out, seed, family, first_chunk, |rng, chunk| {
            chunk.iter_mut().for_each(|x| *x = self.draw(rng));
        });
    }
}

mod statistics;

pub use statistics::*;
