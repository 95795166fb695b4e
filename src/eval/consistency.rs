//! Is the drawn uncertainty honest? For every estimate of a node that Monte Carlo ran for, the
//! fraction of the Monte Carlo samples inside each region the estimate draws at the chosen
//! confidence p (with its binomial standard error), and the ANEES of the samples under the
//! estimate's Gaussian (with the χ² band for the sample size). The one home of the "inside"
//! rule of every region ([`Region`]):
//!
//! - **tangent** (a Gaussian on the group: first order, 2nd/4th order, sigma points, closed
//!   forms, the given Σ of an input, Monte Carlo's own fit): X is inside when
//!   εᵀ Σ⁻¹ ε ≤ χ²_d(p), ε = Log(μ⁻¹X) (right side) or Log(Xμ⁻¹) (left side), with the
//!   method's Σ and side, d the group's degrees of freedom. Its NEES εᵀ Σ⁻¹ ε is what the ANEES
//!   averages (expectation d).
//! - **tangent_position**: the position block of the right-form tangent, ρᵀ Σ_ρρ⁻¹ ρ ≤ χ²_k(p),
//!   ρ the first k entries of Log(μ⁻¹X) (k = 2 planar, 3 in space).
//! - **cartesian**: the sample's world position p, (p − p̄)ᵀ Σ_p⁻¹ (p − p̄) ≤ χ²_k(p), with
//!   p̄ the mean's position and Σ_p = R Σ_ρρ Rᵀ (the ellipse or ellipsoid the viewer draws).
//! - **vector_space**: the same test for the vector-space (Smith–Self–Cheeseman) method, whose
//!   Gaussian lives in (x, y, θ) / (x, y, z, roll, pitch, yaw): its position block is the
//!   ellipse it draws. Its NEES is taken in those coordinates, angle differences wrapped to
//!   (−π, π].
//!
//! A region whose covariance is singular (a direction with no variance) has no coverage: the
//! samples of an exact method never leave it, and any other sample is infinitely far.
//!
//! The samples of a node are independent, so the count inside is binomial and n · ANEES is
//! χ²_{n·d} when the estimate is exact ([`anees_band`]).

use crate::uncertain::Confidence;
use nalgebra::{Matrix2, Matrix3, SVector, Vector3};
use rayon::prelude::*;
use serde::Serialize;

use super::groups::EvalGroup;
use super::model::Estimate;
use crate::lie::{LieGroup, TangentMatrix};
use crate::uncertain::{
    Coverage, Method, Region, Side, anees_band, chi2_radius, try_inverse_covariance,
};

/// Probability of the ANEES band (two-sided).
pub const ANEES_BAND_PROBABILITY: f64 = 0.95;

/// Samples per parallel task.
const TASK_SAMPLES: usize = 4096;

/// How honest one estimate's regions are against the Monte Carlo samples of its node.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Consistency {
    /// The samples counted.
    pub samples: usize,
    /// The confidence p the regions are drawn at.
    pub confidence: Confidence,
    /// Per region the estimate draws: the fraction of samples inside and its standard error.
    pub coverage: Vec<Coverage>,
    /// The average NEES of the samples under the estimate's Gaussian (`None` where its Σ is
    /// singular).
    pub anees: Option<Anees>,
}

/// An average normalised estimation error squared and the band it falls in when the
/// covariance is right.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Anees {
    /// (1/n) Σ εᵢᵀ Σ⁻¹ εᵢ.
    pub value: f64,
    /// The dimension d of ε: the expectation of each NEES.
    pub dof: usize,
    /// The [`ANEES_BAND_PROBABILITY`] band for n samples ([`anees_band`]).
    pub band: [f64; 2],
}

impl Consistency {
    /// The coverage of `region`, if the estimate has it.
    ///
    /// ```
    /// use posecov::eval::Consistency;
    /// use posecov::uncertain::{Confidence, Coverage, Region};
    /// let c = Consistency { samples: 10, confidence: Confidence::DEFAULT, anees: None,
    ///     coverage: vec![Coverage::from_counts(Region::Cartesian, 2, 7, 10)] };
    /// assert_eq!(c.region(Region::Cartesian).unwrap().inside, 0.7);
    /// assert!(c.region(Region::Tangent).is_none());
    /// ```
    pub fn region(&self, region: Region) -> Option<&Coverage> {
        self.coverage.iter().find(|c| c.region == region)
    }
}

/// One method's coverage of one output, for a one-line summary (the live page's status).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CoverageSummary {
    /// The output (its last recorded step for a propagation).
    pub output: String,
    /// The step, for propagations.
    pub step: Option<u64>,
    /// The method's label.
    pub method: &'static str,
    /// The confidence p the regions are drawn at.
    pub confidence: Confidence,
    /// Its regions' coverage.
    pub coverage: Vec<Coverage>,
    /// Its ANEES, where Σ is regular.
    pub anees: Option<Anees>,
}

/// The coverage of the last output's estimates (its last recorded step), Monte Carlo's own
/// fit left out: what a status line shows.
pub(super) fn last_output_summary<G: LieGroup<N>, const N: usize>(
    nodes: &[super::Node<G, N>],
) -> Vec<CoverageSummary> {
    let Some(node) = nodes.iter().rev().find(|n| {
        n.role == super::Role::Output && n.estimates.iter().any(|e| e.consistency.is_some())
    }) else {
        return Vec::new();
    };
    node.estimates
        .iter()
        .filter(|e| e.result.method != Method::MonteCarlo)
        .filter_map(|e| {
            let c = e.consistency.as_ref()?;
            Some(CoverageSummary {
                output: node.name.clone(),
                step: node.step,
                method: e.result.method.label(),
                confidence: c.confidence,
                coverage: c.coverage.clone(),
                anees: c.anees,
            })
        })
        .collect()
}

/// What one sample is tested against for one estimate.
#[derive(Clone)]
struct EstimateTest<G: LieGroup<N>, const N: usize> {
    /// The estimate's index in its node.
    index: usize,
    mean: G,
    /// Σ⁻¹ on the estimate's side (tangent methods).
    tangent: Option<(Side, TangentMatrix<N>)>,
    /// Σ_ρρ⁻¹ of the right form, embedded in a 3×3 (zeros past k).
    tangent_position: Option<Matrix3<f64>>,
    /// The Cartesian or vector-space position region: p̄ and Σ_p⁻¹ (embedded, zeros past k).
    position: Option<(Region, Vector3<f64>, Matrix3<f64>)>,
    /// The vector-space Gaussian: v̄ and Σ_v⁻¹.
    coordinates: Option<(SVector<f64, N>, TangentMatrix<N>)>,
}

/// Per estimate: samples inside the tangent, tangent-position and position regions, and the
/// NEES sum.
#[derive(Clone, Copy, Default)]
struct Counts {
    inside: [u64; 3],
    nees: f64,
}

impl Counts {
    /// Adds `parts` to `totals`, estimate by estimate.
    fn add_all(totals: &mut [Counts], parts: &[Counts]) {
        for (total, part) in totals.iter_mut().zip(parts) {
            for (t, p) in total.inside.iter_mut().zip(part.inside) {
                *t += p;
            }
            total.nees += part.nees;
        }
    }
}

/// Running counts of every estimate of one node over the samples seen so far (all of them at
/// once, or block by block in a blocked run).
pub(super) struct ConsistencySums<G: LieGroup<N>, const N: usize> {
    tests: Vec<EstimateTest<G, N>>,
    counts: Vec<Counts>,
    samples: usize,
    confidence: Confidence,
    /// χ²_d(p) of the tangent and χ²_k(p) of the position regions.
    thresholds: [f64; 2],
}

impl<G: EvalGroup<N>, const N: usize> ConsistencySums<G, N> {
    /// Empty counts for every estimate of `estimates` at confidence `p`; `None` when p is not
    /// a probability.
    pub(super) fn new(estimates: &[Estimate<G, N>], confidence: Confidence) -> Option<Self> {
        let k = G::KIND.position_dims();
        let squared = |d: usize| chi2_radius(confidence.get(), d).ok().map(|r| r * r);
        let thresholds = [squared(N)?, if k > 0 { squared(k)? } else { 0.0 }];
        let tests: Vec<_> = estimates
            .iter()
            .enumerate()
            .map(|(index, e)| estimate_test(index, e))
            .collect();
        Some(Self {
            counts: vec![Counts::default(); tests.len()],
            tests,
            samples: 0,
            confidence,
            thresholds,
        })
    }

    /// Counts `samples`.
    pub(super) fn add(&mut self, samples: &[G]) {
        let tests = &self.tests;
        let thresholds = self.thresholds;
        let zero = || vec![Counts::default(); tests.len()];
        let sums = samples
            .par_chunks(TASK_SAMPLES)
            .map(|chunk| {
                let mut counts = zero();
                for x in chunk {
                    for (test, c) in tests.iter().zip(&mut counts) {
                        test.count(x, thresholds, c);
                    }
                }
                counts
            })
            .reduce(zero, |mut a, b| {
                Counts::add_all(&mut a, &b);
                a
            });
        Counts::add_all(&mut self.counts, &sums);
        self.samples += samples.len();
    }

    /// Writes each counted estimate's [`Consistency`] into `estimates` (the same slice, or
    /// one that starts with it, as [`new`](Self::new) saw).
    pub(super) fn finish(&self, estimates: &mut [Estimate<G, N>]) {
        if self.samples == 0 {
            return;
        }
        let n = self.samples;
        let k = G::KIND.position_dims();
        for (test, counts) in self.tests.iter().zip(&self.counts) {
            let Some(estimate) = estimates.get_mut(test.index) else {
                continue;
            };
            let mut coverage = Vec::new();
            let mut add = |region: Region, dof: usize, inside: u64| {
                coverage.push(Coverage::from_counts(region, dof, inside as usize, n));
            };
            if test.tangent.is_some() {
                add(Region::Tangent, N, counts.inside[0]);
            }
            if test.tangent_position.is_some() {
                add(Region::TangentPosition, k, counts.inside[1]);
            }
            if let Some((region, ..)) = test.position {
                add(region, k, counts.inside[2]);
            }
            let nees_dof = (test.tangent.is_some() || test.coordinates.is_some()).then_some(N);
            let anees = nees_dof.and_then(|dof| {
                Some(Anees {
                    value: counts.nees / n as f64,
                    dof,
                    band: anees_band(n, dof, ANEES_BAND_PROBABILITY).ok()?,
                })
            });
            estimate.consistency = Some(Consistency {
                samples: n,
                confidence: self.confidence,
                coverage,
                anees,
            });
        }
    }
}

impl<G: EvalGroup<N>, const N: usize> EstimateTest<G, N> {
    /// Adds sample `x` to `c`.
    fn count(&self, x: &G, thresholds: [f64; 2], c: &mut Counts) {
        let right = (self.tangent.is_some() || self.tangent_position.is_some())
            .then(|| x.rminus(&self.mean));
        if let Some((side, info)) = &self.tangent {
            let e = match (side, right) {
                (Side::Right, Some(r)) => r,
                _ => x.lminus(&self.mean),
            };
            let nees = e.dot(&(info * e));
            c.inside[0] += u64::from(nees <= thresholds[0]);
            c.nees += nees;
        }
        if let (Some(info), Some(r)) = (&self.tangent_position, right) {
            let rho = Vector3::from_fn(|i, _| if i < N { r[i] } else { 0.0 });
            c.inside[1] += u64::from(rho.dot(&(info * rho)) <= thresholds[1]);
        }
        if let Some((_, centre, info)) = &self.position {
            let d = x.to_se3().translation() - centre;
            c.inside[2] += u64::from(d.dot(&(info * d)) <= thresholds[1]);
        }
        if let Some((mean, info)) = &self.coordinates
            && let Some(v) = G::coordinates(x)
        {
            let mut e = v - mean;
            for i in G::rotation_range() {
                e[i] = wrap_angle(e[i]);
            }
            c.nees += e.dot(&(info * e));
        }
    }
}

/// What to test a sample against for estimate `index`.
fn estimate_test<G: EvalGroup<N>, const N: usize>(
    index: usize,
    estimate: &Estimate<G, N>,
) -> EstimateTest<G, N> {
    let pose = &estimate.result.pose;
    let k = G::KIND.position_dims();
    let mean = *pose.mean();
    let mut test = EstimateTest {
        index,
        mean,
        tangent: None,
        tangent_position: None,
        position: None,
        coordinates: None,
    };
    let centre = *mean.to_se3().translation();
    let world = pose.position_cov_in_world_3d();
    if estimate.result.method == Method::VectorSpace {
        test.position = world
            .and_then(|c| inverse_block(&c, k))
            .map(|info| (Region::VectorSpace, centre, info));
        test.coordinates = G::coordinates_gaussian(pose)
            .and_then(|(v, cov)| Some((v, try_inverse_covariance("Σ_v", &cov).ok()?)));
        return test;
    }
    test.tangent = try_inverse_covariance("Σ", pose.cov())
        .ok()
        .map(|info| (pose.side(), info));
    if k > 0 {
        let right = pose.cov_right();
        let block = Matrix3::from_fn(|r, c| if r < k && c < k { right[(r, c)] } else { 0.0 });
        test.tangent_position = inverse_block(&block, k);
        test.position = world
            .and_then(|c| inverse_block(&c, k))
            .map(|info| (Region::Cartesian, centre, info));
    }
    test
}

/// The inverse of the leading k×k block of `cov` (k = 2 or 3), embedded in a 3×3 with zeros
/// elsewhere; `None` when the block is singular or not a covariance.
fn inverse_block(cov: &Matrix3<f64>, k: usize) -> Option<Matrix3<f64>> {
    match k {
        2 => {
            let block: Matrix2<f64> = cov.fixed_view::<2, 2>(0, 0).into_owned();
            let info = try_inverse_covariance("Σ_p", &block).ok()?;
            Some(Matrix3::from_fn(|r, c| {
                if r < 2 && c < 2 { info[(r, c)] } else { 0.0 }
            }))
        }
        3 => try_inverse_covariance("Σ_p", cov).ok(),
        _ => None,
    }
}

/// An angle difference wrapped to (−π, π].
fn wrap_angle(a: f64) -> f64 {
    let wrapped = a - std::f64::consts::TAU * (a / std::f64::consts::TAU).round();
    if wrapped <= -std::f64::consts::PI {
        wrapped + std::f64::consts::TAU
    } else {
        wrapped
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lie::{Se2, So3};
    use crate::propagate::Propagated;
    use crate::sample::Sampler;
    use crate::uncertain::UncertainPose;

    fn estimate<G: LieGroup<N>, const N: usize>(
        pose: UncertainPose<G, N>,
        method: Method,
    ) -> Estimate<G, N> {
        Estimate {
            result: Propagated { pose, method },
            error_vs_monte_carlo: None,
            consistency: None,
        }
    }

    #[test]
    fn samples_of_the_estimate_itself_are_covered_at_the_confidence() {
        let pose = UncertainPose::try_from_std_devs(
            Se2::from_xy_theta(1.0, 2.0, 0.7),
            [0.3, 0.1, 0.4],
            Side::Left,
        )
        .unwrap();
        let samples = Sampler::new(&pose).unwrap().draw_par(40_000, 3);
        let mut estimates = vec![estimate(pose, Method::FirstOrder)];
        let mut sums = ConsistencySums::new(&estimates, Confidence::new(0.9).unwrap()).unwrap();
        sums.add(&samples[..15_000]);
        sums.add(&samples[15_000..]);
        sums.finish(&mut estimates);
        let c = estimates[0].consistency.as_ref().unwrap();
        let tangent = c.region(Region::Tangent).unwrap();
        assert_eq!((tangent.dof, c.samples), (3, 40_000));
        assert!((tangent.inside - 0.9).abs() < 4.0 * tangent.stderr, "{c:?}");
        let anees = c.anees.unwrap();
        assert!(
            anees.band[0] < anees.value && anees.value < anees.band[1],
            "{anees:?}"
        );
        // A left-side Σ's right-form position block is what tangent_position reads.
        let position = c.region(Region::TangentPosition).unwrap();
        assert_eq!(position.dof, 2);
        assert!(
            (position.inside - 0.9).abs() < 4.0 * position.stderr,
            "{c:?}"
        );
    }

    #[test]
    fn an_overconfident_estimate_leaves_the_band_above_and_a_singular_one_has_no_tangent() {
        let truth = UncertainPose::try_from_std_devs(So3::identity(), [0.2, 0.1, 0.3], Side::Right)
            .unwrap();
        let small =
            UncertainPose::try_from_std_devs(So3::identity(), [0.1, 0.05, 0.15], Side::Right)
                .unwrap();
        let singular =
            UncertainPose::try_from_std_devs(So3::identity(), [0.1, 0.0, 0.1], Side::Right)
                .unwrap();
        let samples = Sampler::new(&truth).unwrap().draw_par(5_000, 1);
        let mut estimates = vec![
            estimate(small, Method::FirstOrder),
            estimate(singular, Method::SigmaPoints),
        ];
        let mut sums = ConsistencySums::new(&estimates, Confidence::DEFAULT).unwrap();
        sums.add(&samples);
        sums.finish(&mut estimates);
        let c = estimates[0].consistency.as_ref().unwrap();
        let anees = c.anees.unwrap();
        assert!((anees.value - 12.0).abs() < 0.6, "{anees:?}"); // 4 · d on average
        assert!(anees.value > anees.band[1]);
        assert!(c.region(Region::TangentPosition).is_none()); // SO(3) has no position
        let s = estimates[1].consistency.as_ref().unwrap();
        assert!(s.coverage.is_empty() && s.anees.is_none(), "{s:?}");
    }

    #[test]
    fn angle_differences_wrap_into_half_open_interval() {
        use std::f64::consts::PI;
        assert!((wrap_angle(2.0 * PI - 0.1) + 0.1).abs() < 1e-12);
        assert_eq!(wrap_angle(-PI), PI);
        assert!((wrap_angle(0.3) - 0.3).abs() < 1e-15);
    }
}
