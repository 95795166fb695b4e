//! What the engine reports besides estimates: a method that failed for an output, and a
//! covariance that is not positive semi-definite (one finding per output and method, later
//! steps counted).

use super::engine::Engine;
use super::groups::EvalGroup;
use super::model::{FailureReason, Finding};
use crate::lie::TangentMatrix;
use crate::uncertain::Method;
use nalgebra::{DMatrix, SymmetricEigen};

impl<G: EvalGroup<N>, const N: usize> Engine<'_, '_, G, N> {
    /// A finding that a method failed for the current output.
    pub(super) fn method_failed(
        &mut self,
        step: Option<u64>,
        method: Method,
        reason: FailureReason,
    ) {
        let output = &self.current.output;
        // One finding per output and method: later steps are counted, not repeated.
        for f in &mut self.out.findings {
            if let Finding::MethodFailed {
                output: o,
                method: m,
                later_steps,
                ..
            } = f
                && o == output
                && *m == method
            {
                *later_steps += 1;
                return;
            }
        }
        self.out.findings.push(Finding::MethodFailed {
            output: output.clone(),
            step,
            method,
            reason,
            later_steps: 0,
        });
    }

    /// Reports a covariance that is not positive semi-definite (smallest eigenvalue below
    /// −[`psd_tolerance`](crate::uncertain::psd_tolerance) of the largest).
    pub(super) fn check_psd(
        &mut self,
        name: &str,
        step: Option<u64>,
        method: Method,
        cov: &TangentMatrix<N>,
    ) {
        let sym = (cov + cov.transpose()) * 0.5;
        let eig = SymmetricEigen::new(DMatrix::from_iterator(N, N, sym.iter().copied()));
        let smallest = eig.eigenvalues.min();
        let largest = eig.eigenvalues.max();
        if smallest < -crate::uncertain::psd_tolerance(largest) {
            for f in &mut self.out.findings {
                if let Finding::NotPositiveSemiDefinite {
                    output,
                    method: m,
                    later_steps,
                    ..
                } = f
                    && output == name
                    && *m == method
                {
                    *later_steps += 1;
                    return;
                }
            }
            self.out.findings.push(Finding::NotPositiveSemiDefinite {
                output: name.to_owned(),
                step,
                method,
                smallest_eigenvalue: smallest,
                largest_eigenvalue: largest,
                later_steps: 0,
            });
        }
    }
}
