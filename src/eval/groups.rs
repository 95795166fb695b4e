//! Group-specific operations of the evaluator: what only some groups can do
//! (differential drive on SE(2), Euler vs Exp on SO(3), compounding and the vector-space
//! baseline on SE(2)/SE(3)), behind one trait the generic engine calls.

use nalgebra::{Matrix3, SVector, Vector3};

use crate::interop::{VectorChart, to_coordinates};
use crate::lie::{LieGroup, Se2, Se3, So2, So3, TangentMatrix};
use crate::plan::DiffDriveMotion;
use crate::propagate::Propagated;
use crate::propagate::diff_drive::{DiffDrive, EulerMaruyama};
use crate::propagate::first_order;
use crate::propagate::fourth_order::{self, Order};
use crate::propagate::vector_space::{VectorPose, ssc_compose, ssc_odometry};
use crate::uncertain::UncertainPose;

/// Group-specific operations the generic engine asks for; `None` where a group has none.
pub trait EvalGroup<const N: usize>: LieGroup<N> {
    /// An uncertain point p (covariance Σ_p, in the pose's frame; planar groups read x, y)
    /// seen from an uncertain pose, to first order: (mean, covariance) in world coordinates,
    /// lifted to 3D (z = 0 in the plane).
    fn point_through(
        pose: &UncertainPose<Self, N>,
        point: &Vector3<f64>,
        cov: &Matrix3<f64>,
    ) -> crate::Result<(Vector3<f64>, Matrix3<f64>)>;

    /// 2nd/4th-order compounding Z = X·Y (Barfoot & Furgale 2014), where defined.
    fn compound(
        _x: &UncertainPose<Self, N>,
        _y: &UncertainPose<Self, N>,
        _order: Order,
    ) -> Option<Propagated<Self, N>> {
        None
    }

    /// Smith–Self–Cheeseman compose in the group's vector coordinates, where defined.
    fn ssc_compose(
        _x: &UncertainPose<Self, N>,
        _y: &UncertainPose<Self, N>,
    ) -> Option<crate::Result<Propagated<Self, N>>> {
        None
    }

    /// Smith–Self–Cheeseman odometry (increments as group elements, noise read in the vector
    /// coordinates), where defined; one result per step including the start.
    fn ssc_odometry(
        _start: &UncertainPose<Self, N>,
        _increments: &[Self],
        _noise: &TangentMatrix<N>,
    ) -> Option<crate::Result<Vec<Propagated<Self, N>>>> {
        None
    }

    /// Differential drive (Long et al. 2012), SE(2) only: closed form, the numeric integral
    /// (when `integral`) and `samples` Euler–Maruyama end poses from chunk `first_chunk` of
    /// the stream `seed`.
    fn diff_drive(
        _motion: &DiffDriveMotion,
        _integral: bool,
        _samples: usize,
        _first_chunk: u64,
        _seed: u64,
    ) -> Option<crate::Result<DiffDriveOutcome<Self, N>>> {
        None
    }

    /// The vector-space coordinates φ(X) ([`VectorChart`]), where the group has them.
    fn coordinates(_x: &Self) -> Option<SVector<f64, N>> {
        None
    }

    /// An uncertain pose in vector-space coordinates, first order: (φ(μ), J Σ_right Jᵀ)
    /// ([`to_coordinates`]), where the group has them and the chart is regular there.
    fn coordinates_gaussian(
        _pose: &UncertainPose<Self, N>,
    ) -> Option<(SVector<f64, N>, TangentMatrix<N>)> {
        None
    }

    /// Euler integration vs the exponential map, SO(3) only: per step (Euler matrix, Exp element).
    fn euler_vs_exp(
        _rate: &Vector3<f64>,
        _dt: f64,
        _steps: u64,
    ) -> Option<Vec<(Matrix3<f64>, Self)>> {
        None
    }
}

/// What a differential-drive run produces.
#[derive(Debug, Clone)]
pub struct DiffDriveOutcome<G: LieGroup<N>, const N: usize> {
    /// Closed form and numeric integral (relative to the start pose).
    pub estimates: Vec<Propagated<G, N>>,
    /// Euler–Maruyama end poses.
    pub end_poses: Vec<G>,
    /// A few sampled trajectories.
    pub trajectories: Vec<Vec<G>>,
    /// The nominal path.
    pub nominal_path: Vec<G>,
}

/// Trajectories kept from the SDE sampling, for drawing.
const DIFF_DRIVE_TRAJECTORIES: usize = 30;

/// First-order point through pose for a group acting on ℝᴰ, lifted to 3D (z = 0 in the plane).
fn point_estimate<G, const N: usize, const D: usize>(
    pose: &UncertainPose<G, N>,
    point: &Vector3<f64>,
    cov: &Matrix3<f64>,
) -> crate::Result<(Vector3<f64>, Matrix3<f64>)>
where
    G: LieGroup<
            N,
            Point = nalgebra::SVector<f64, D>,
            ActJacobian = nalgebra::SMatrix<f64, D, N>,
            PointJacobian = nalgebra::SMatrix<f64, D, D>,
        >,
{
    let p = nalgebra::SVector::<f64, D>::from_iterator(point.iter().copied());
    let c = cov.fixed_view::<D, D>(0, 0).into_owned();
    let q = first_order::act_point(pose, &p, &c)?;
    let mut mean = Vector3::zeros();
    let mut cov3 = Matrix3::zeros();
    mean.fixed_rows_mut::<D>(0).copy_from(&q.mean);
    cov3.fixed_view_mut::<D, D>(0, 0).copy_from(&q.cov);
    Ok((mean, cov3))
}

fn ssc_compose_in<G: VectorChart<N>, const N: usize>(
    x: &UncertainPose<G, N>,
    y: &UncertainPose<G, N>,
) -> crate::Result<Propagated<G, N>> {
    ssc_compose(
        &VectorPose::from_uncertain(x)?,
        &VectorPose::from_uncertain(y)?,
    )?
    .to_uncertain()
}

fn ssc_odometry_in<G: VectorChart<N>, const N: usize>(
    start: &UncertainPose<G, N>,
    increments: &[G],
    noise: &TangentMatrix<N>,
) -> crate::Result<Vec<Propagated<G, N>>> {
    let coordinates: Vec<_> = increments.iter().map(VectorChart::to_coordinates).collect();
    ssc_odometry(&VectorPose::from_uncertain(start)?, &coordinates, noise)?
        .iter()
        .map(VectorPose::to_uncertain)
        .collect()
}

impl EvalGroup<1> for So2 {
    fn point_through(
        pose: &UncertainPose<Self, 1>,
        point: &Vector3<f64>,
        cov: &Matrix3<f64>,
    ) -> crate::Result<(Vector3<f64>, Matrix3<f64>)> {
        point_estimate::<Self, 1, 2>(pose, point, cov)
    }
}

impl EvalGroup<3> for So3 {
    fn point_through(
        pose: &UncertainPose<Self, 3>,
        point: &Vector3<f64>,
        cov: &Matrix3<f64>,
    ) -> crate::Result<(Vector3<f64>, Matrix3<f64>)> {
        point_estimate::<Self, 3, 3>(pose, point, cov)
    }
    fn euler_vs_exp(rate: &Vector3<f64>, dt: f64, steps: u64) -> Option<Vec<(Matrix3<f64>, Self)>> {
        let step = rate * dt;
        let increment = Matrix3::identity() + So3::hat(&step);
        let mut euler = Matrix3::identity();
        let mut exp = So3::identity();
        let mut out = vec![(euler, exp)];
        for _ in 0..steps {
            euler *= increment;
            exp = exp.rplus(&step);
            out.push((euler, exp));
        }
        Some(out)
    }
}

/// The operations SE(2) and SE(3) share: point through pose, 2nd/4th-order compounding, and
/// the Smith–Self–Cheeseman baseline in their vector coordinates.
macro_rules! pose_group_ops {
    ($N:literal, $D:literal, $compound:path) => {
        fn point_through(
            pose: &UncertainPose<Self, $N>,
            point: &Vector3<f64>,
            cov: &Matrix3<f64>,
        ) -> crate::Result<(Vector3<f64>, Matrix3<f64>)> {
            point_estimate::<Self, $N, $D>(pose, point, cov)
        }
        fn compound(
            x: &UncertainPose<Self, $N>,
            y: &UncertainPose<Self, $N>,
            order: Order,
        ) -> Option<Propagated<Self, $N>> {
            Some($compound(x, y, order))
        }
        fn ssc_compose(
            x: &UncertainPose<Self, $N>,
            y: &UncertainPose<Self, $N>,
        ) -> Option<crate::Result<Propagated<Self, $N>>> {
            Some(ssc_compose_in(x, y))
        }
        fn coordinates(x: &Self) -> Option<SVector<f64, $N>> {
            Some(x.to_coordinates())
        }
        fn coordinates_gaussian(
            pose: &UncertainPose<Self, $N>,
        ) -> Option<(SVector<f64, $N>, TangentMatrix<$N>)> {
            to_coordinates(pose).ok()
        }
        fn ssc_odometry(
            start: &UncertainPose<Self, $N>,
            increments: &[Self],
            noise: &TangentMatrix<$N>,
        ) -> Option<crate::Result<Vec<Propagated<Self, $N>>>> {
            Some(ssc_odometry_in(start, increments, noise))
        }
    };
}

impl EvalGroup<3> for Se2 {
    pose_group_ops!(3, 2, fourth_order::compound_se2);

    fn diff_drive(
        p: &DiffDriveMotion,
        integral: bool,
        samples: usize,
        first_chunk: u64,
        seed: u64,
    ) -> Option<crate::Result<DiffDriveOutcome<Self, 3>>> {
        Some((|| {
            let robot = DiffDrive::try_new(p.wheel_radius, p.wheelbase, p.diffusion)?;
            let closed = if p.turn_rate == 0.0 {
                robot.straight_closed_form(p.speed, p.duration)?
            } else {
                robot.arc_closed_form(p.speed, p.turn_rate, p.duration)?
            };
            let rates = robot.wheel_rates_for(p.speed, p.turn_rate);
            let mut estimates = vec![closed];
            if integral {
                estimates.push(robot.numeric_integral(rates, p.duration, 1e-12)?);
            }
            let nominal_path = (0..=100)
                .map(|i| robot.nominal(rates, p.duration * f64::from(i) / 100.0))
                .collect();
            let (end_poses, trajectories) = if samples > 0 {
                let settings = EulerMaruyama::new(p.dt, samples, seed)
                    .with_trajectories(DIFF_DRIVE_TRAJECTORIES, 10)
                    .starting_at_chunk(first_chunk);
                let sde = robot.euler_maruyama(rates, p.duration, &settings)?;
                (sde.end_poses, sde.trajectories)
            } else {
                (Vec::new(), Vec::new())
            };
            Ok(DiffDriveOutcome {
                estimates,
                end_poses,
                trajectories,
                nominal_path,
            })
        })())
    }
}

impl EvalGroup<6> for Se3 {
    pose_group_ops!(6, 3, fourth_order::compound_se3);
}
