//! `[draw] camera` and `[methods.sigma_points]`: checked where they are read, each error at the
//! table's `file:line:column` with the key and the value.

use toml::Spanned;

use super::Lowering;
use crate::input::CameraChoice;
use crate::input::scenario::ScenarioError;
use crate::input::scenario::schema::{CameraSpec, SigmaPointsSpec};
use crate::propagate::sigma_point::Unscented;

/// The largest camera coordinate accepted (m): squares and sums of it stay finite.
const CAMERA_LIMIT: f64 = 1e9;

impl Lowering<'_> {
    /// `[draw] camera`: finite numbers within ±1e9 m; `position` or `direction`, not both; a non-zero
    /// `direction` and `up`; the eye not at its target; `up` not along the line of sight.
    pub(super) fn camera(
        &self,
        spec: &Option<Spanned<CameraSpec>>,
    ) -> Result<Option<CameraChoice>, ScenarioError> {
        let Some(spec) = spec else { return Ok(None) };
        let c = spec.get_ref();
        let fail = |message: String| Err(self.err(spec.span(), "draw.camera", message));
        let named = [
            ("position", c.position),
            ("direction", c.direction),
            ("target", c.target),
            ("up", c.up),
        ];
        for (key, v) in named {
            if let Some(v) = v.filter(|v| v.iter().any(|x| !x.is_finite())) {
                return fail(format!("{key} = {v:?} is not three finite numbers"));
            }
            if let Some(v) = v.filter(|v| v.iter().any(|x| x.abs() > CAMERA_LIMIT)) {
                return fail(format!(
                    "{key} = {v:?} is beyond ±{CAMERA_LIMIT:e} m (a camera is placed in the scene's metres)"
                ));
            }
        }
        let norm = |v: [f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if c.position.is_some() && c.direction.is_some() {
            return fail("give `position` or `direction`, not both".to_owned());
        }
        for (key, v) in [("direction", c.direction), ("up", c.up)] {
            if let Some(v) = v.filter(|v| norm(*v) == 0.0) {
                return fail(format!("{key} = {v:?} has no direction"));
            }
        }
        let sight = match (c.position, c.target, c.direction) {
            (Some(p), Some(t), _) => Some([0, 1, 2].map(|i| p[i] - t[i])),
            (_, _, d) => d,
        };
        if let Some(s) = sight {
            if norm(s) < 1e-6 {
                return fail("the eye `position` is at its `target`".to_owned());
            }
            let up = c.up.unwrap_or([0.0, 0.0, 1.0]);
            let cos = (s[0] * up[0] + s[1] * up[1] + s[2] * up[2]) / (norm(s) * norm(up));
            if cos.abs() > 0.5f64.to_radians().cos() {
                return fail(format!(
                    "up = {up:?} lies along the line of sight: choose another `up` (e.g. [0, 1, 0] for a view from straight above)"
                ));
            }
        }
        Ok(Some(CameraChoice {
            position: c.position,
            direction: c.direction,
            target: c.target,
            up: c.up,
        }))
    }

    /// `[methods.sigma_points]`: finite α > 0, β, κ with L + κ > 0 for the smallest L an
    /// operation has (the group's DOF, one input).
    pub(super) fn sigma_points(
        &self,
        spec: &Option<Spanned<SigmaPointsSpec>>,
        dof: usize,
    ) -> Result<Option<Unscented>, ScenarioError> {
        let Some(spec) = spec else { return Ok(None) };
        let s = spec.get_ref();
        let d = Unscented::default();
        let params = Unscented {
            alpha: s.alpha.unwrap_or(d.alpha),
            beta: s.beta.unwrap_or(d.beta),
            kappa: s.kappa.unwrap_or(d.kappa),
            side: d.side,
        };
        let fail = |key: &str, value: f64, expected: String| {
            Err(self.err(
                spec.span(),
                &format!("methods.sigma_points.{key}"),
                format!("{value} is out of range: {expected}"),
            ))
        };
        if !(params.alpha.is_finite() && params.alpha > 0.0) {
            return fail("alpha", params.alpha, "a finite α > 0, e.g. 1".to_owned());
        }
        if !params.beta.is_finite() {
            return fail("beta", params.beta, "a finite β, e.g. 2".to_owned());
        }
        if !(params.kappa.is_finite() && dof as f64 + params.kappa > 0.0) {
            return fail(
                "kappa",
                params.kappa,
                format!("a finite κ > −{dof} (L + κ > 0 for every operation; L ≥ {dof} here)"),
            );
        }
        Ok(Some(params))
    }
}
