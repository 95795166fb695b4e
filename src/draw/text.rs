//! The text panel: the title, then the tables — each method's error against Monte Carlo and
//! the samples its regions hold, the methods and their colours — and the run's along-track
//! numbers, then the prose: the input's own description, its source, the convention, and
//! every finding of the evaluation. Tables first, so they show at 1024 × 640, and narrow (one
//! per pose, short cells and a key), so the panel wraps its prose to its own width.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::{DrawSettings, words};
use crate::eval::{Consistency, Evaluation, FailureReason, Finding, Node, Role};
use crate::lie::{GroupKind, LieGroup};
use crate::uncertain::{Coverage, Method, Region};

/// The Markdown of the text panel.
pub(super) fn description<G: LieGroup<N>, const N: usize>(
    e: &Evaluation<G, N>,
    settings: &DrawSettings,
) -> String {
    let about = &settings.about;
    let fill = |text: &str| words::fill(text, e, settings.confidence);
    // The title, then the tables and the run's numbers, then the prose: at 1024 × 640 the
    // panel shows its top, so that is where the numbers go.
    let mut s = format!("## {}\n\n", fill(&about.title));
    let caption = errors_table(&mut s, e);
    if !e.methods.is_empty() {
        let _ = writeln!(s, "| method | colour |\n|---|---|");
        for method in &e.methods {
            let _ = writeln!(s, "| {} | {} |", method.label(), method.color_name());
        }
        if e.methods.contains(&Method::MonteCarlo) {
            let _ = writeln!(
                s,
                "| Monte Carlo samples | grey cloud ({} samples, seed {}) |",
                e.samples, e.seed
            );
        }
        s.push('\n');
    }
    along_track(&mut s, e);
    s.push_str(&caption);
    let own = super::input_description(about, &settings.choices);
    let _ = writeln!(s, "{}", fill(own.trim()));
    if let Some(g) = &e.graph {
        s.push_str(&super::graph::describe(g));
    }
    s.push('\n');
    if !about.source.is_empty() {
        let _ = writeln!(s, "*Source: {}*\n", about.source);
    }
    let _ = writeln!(
        s,
        "**Convention:** {} with tangent order {}; covariances are read as X = μ · Exp(ε) (right / body) unless marked left. \
         Regions are drawn at {:.1} % confidence (χ² radius {:.3} for the {}-DOF tangent ellipsoid).\n",
        G::NAME,
        tangent_order(G::KIND),
        settings.confidence.get() * 100.0,
        settings.confidence.radius(N),
        N
    );
    if e.methods.contains(&Method::SigmaPoints) {
        let u = &e.unscented;
        let _ = writeln!(
            s,
            "**Sigma points** (Julier & Uhlmann 2004; α = {}, β = {}, κ = {}): 2L + 1 points at ±γ·√Σ, γ = α√(L + κ), \
             L the inputs' tangent dimensions. For compose, between and inverse of independent inputs they equal first order \
             while every sigma point turns less than π.\n",
            u.alpha, u.beta, u.kappa
        );
    }
    for finding in &e.findings {
        let _ = writeln!(s, "{}\n", finding_text(finding));
    }
    s
}

/// Per compounding, every method's along-track variance at its last step; Monte Carlo's with
/// its standard error by batch means ([`crate::eval::batch_means`]).
fn along_track<G: LieGroup<N>, const N: usize>(s: &mut String, e: &Evaluation<G, N>) {
    let values = e.along_track();
    let mut outputs: Vec<&str> = Vec::new();
    for a in &values {
        if !outputs.contains(&a.output.as_str()) {
            outputs.push(&a.output);
        }
    }
    for output in outputs {
        let Some(step) = values
            .iter()
            .filter(|a| a.output == output)
            .map(|a| a.step)
            .max()
        else {
            continue;
        };
        let at_last: Vec<_> = values
            .iter()
            .filter(|a| a.output == output && a.step == step)
            .collect();
        let summary: Vec<String> = at_last
            .iter()
            .map(|a| {
                format!(
                    "{} {}",
                    a.method.label(),
                    words::plus_minus(a.variance_m2, a.stderr_m2, 4)
                )
            })
            .collect();
        let _ = write!(
            s,
            "Along-track variance Σ_ρxρx of `{output}` (world frame, left form, m²) at step {step}: {}",
            summary.join(", ")
        );
        if at_last.iter().any(|a| a.stderr_m2.is_some()) {
            let _ = write!(
                s,
                " (Monte Carlo ± its standard error by batch means over {} batches of the {} samples)",
                crate::eval::batch_means::BATCHES,
                e.samples
            );
        }
        s.push_str(".\n\n");
    }
}

/// Each final node's methods: their error against Monte Carlo and how many Monte Carlo
/// samples their regions hold ([`crate::eval::consistency`]): the banana (tangent region) and
/// the Cartesian (or vector-space) ellipse, and the ANEES against its band. One narrow table
/// per pose, the pose naming its first column, so the tables fit the text panel at
/// 1024 × 640 (a pose column and a verdict column cut the ANEES off there); a verdict is one
/// short word, said in full in the key under the tables. Writes the tables and the key;
/// returns what their columns mean, for after the tables (empty without a table).
fn errors_table<G: LieGroup<N>, const N: usize>(s: &mut String, e: &Evaluation<G, N>) -> String {
    let finals = final_nodes(e);
    let with_errors: Vec<_> = finals
        .iter()
        .filter(|n| {
            n.estimates
                .iter()
                .any(|x| x.error_vs_monte_carlo.is_some() || x.consistency.is_some())
        })
        .collect();
    if with_errors.is_empty() {
        return String::new();
    }
    let measured: Vec<&Consistency> = with_errors
        .iter()
        .flat_map(|n| &n.estimates)
        .filter_map(|x| x.consistency.as_ref())
        .collect();
    let ellipse = |c: &Consistency| {
        c.region(Region::Cartesian)
            .or(c.region(Region::VectorSpace))
            .copied()
    };
    let has_ellipse = measured.iter().any(|c| ellipse(c).is_some());
    let caption = errors_caption::<N>(&measured, G::KIND);
    let mut header_rest = " error |".to_owned();
    let mut rule = "|---|---|".to_owned();
    if !measured.is_empty() {
        header_rest.push_str(if G::KIND.is_rotation_only() {
            " tangent |"
        } else {
            " banana |"
        });
        rule.push_str("---|");
        if has_ellipse {
            header_rest.push_str(" ellipse |");
            rule.push_str("---|");
        }
        header_rest.push_str(" ANEES |");
        rule.push_str("---|");
    }
    let percent =
        |c: Option<Coverage>| c.map_or("–".to_owned(), |c| format!("{:.1} %", 100.0 * c.inside));
    let (mut given, mut over, mut under) = (false, false, false);
    for node in with_errors {
        let label = node.step.map_or(format!("`{}`", node.name), |k| {
            format!("`{}` (step {k})", node.name)
        });
        let _ = writeln!(s, "| {label} |{header_rest}\n{rule}");
        for est in &node.estimates {
            let c = est.consistency.as_ref();
            if est.result.method == Method::MonteCarlo && c.is_none() {
                continue;
            }
            let method = if node.role == Role::Input && est.result.method == Method::Exact {
                given = true;
                "given Σ (noise floor)"
            } else {
                est.result.method.label()
            };
            let error = match (est.result.method, est.error_vs_monte_carlo) {
                (Method::MonteCarlo, _) | (_, None) => "–".to_owned(),
                (_, Some(err)) => format!("{:.1} %", 100.0 * err),
            };
            let mut row = format!("| {method} | {error} |");
            if !measured.is_empty() {
                let _ = write!(
                    row,
                    " {} |",
                    percent(c.and_then(|c| c.region(Region::Tangent).copied()))
                );
                if has_ellipse {
                    let _ = write!(row, " {} |", percent(c.and_then(ellipse)));
                }
                let anees = c.and_then(|c| c.anees).map_or("–".to_owned(), |a| {
                    let verdict = if a.value > a.band[1] {
                        over = true;
                        " **over**"
                    } else if a.value < a.band[0] {
                        under = true;
                        " *under*"
                    } else {
                        ""
                    };
                    format!("{:.2}{verdict}", a.value)
                });
                let _ = write!(row, " {anees} |");
            }
            let _ = writeln!(s, "{row}");
        }
        s.push('\n');
    }
    // The key: the words the narrow cells leave out.
    let mut key = Vec::new();
    if given {
        key.push(
            "*given Σ (noise floor)*: the input's own Σ against its samples, the sampling noise floor of the errors".to_owned(),
        );
    }
    if let Some(a) = measured.iter().find_map(|c| c.anees) {
        if over {
            key.push(format!(
                "**over**: overconfident, the ANEES above its 95 % band {:.2}–{:.2} (Σ too small)",
                a.band[0], a.band[1]
            ));
        }
        if under {
            key.push(format!(
                "*under*: underconfident, the ANEES below its 95 % band {:.2}–{:.2} (Σ too large)",
                a.band[0], a.band[1]
            ));
        }
    }
    if !key.is_empty() {
        let _ = writeln!(s, "{}.\n", key.join("; "));
    }
    caption
}

/// What the columns of [`errors_table`] mean.
fn errors_caption<const N: usize>(measured: &[&Consistency], kind: GroupKind) -> String {
    let mut caption = String::new();
    let _ = write!(
        caption,
        "**Against Monte Carlo** (the first tables): the error ‖Σ − Σ_MC‖_F / ‖Σ_MC‖_F (right side)"
    );
    if let Some(first) = measured.first() {
        let worst = measured
            .iter()
            .flat_map(|c| &c.coverage)
            .map(|c| c.stderr)
            .fold(0.0, f64::max);
        let region = if kind.is_rotation_only() {
            format!("the **tangent** region (d = {N})")
        } else {
            format!(
                "the **banana** (the tangent region, d = {N}) and the **ellipse** (Cartesian, k = {})",
                kind.position_dims()
            )
        };
        let _ = write!(
            caption,
            "; the share of the {} samples inside {region}, both drawn at {:.1} % (standard error ≤ {:.1} %)",
            first.samples,
            first.confidence.get() * 100.0,
            worst * 100.0
        );
        if let Some(a) = measured.iter().find_map(|c| c.anees) {
            let _ = write!(
                caption,
                "; and the ANEES, the samples' average εᵗΣ⁻¹ε: {} when Σ is right, 95 % band {:.2}–{:.2}",
                a.dof, a.band[0], a.band[1]
            );
        }
    }
    caption.push_str(".\n\n");
    caption
}

/// What a finding says, in one paragraph.
fn finding_text(f: &Finding) -> String {
    let at = |step: &Option<u64>| step.map_or(String::new(), |k| format!(" at step {k}"));
    match f {
        Finding::Blocked {
            samples,
            blocks,
            block_samples,
            passes,
        } => format!(
            "Monte Carlo: {samples} samples simulated in {blocks} blocks of {block_samples} to bound memory; the statistics \
             use every sample ({passes} passes of the Lie-mean iteration); the clouds of samples beyond the first block are logged block by block."
        ),
        Finding::Fusion {
            output,
            inputs,
            cost,
            iterations,
        } => format!(
            "Fusion of {inputs} estimates into `{output}`: final cost V = ½ Σ eᵢᵗ Σᵢ⁻¹ eᵢ = {cost:.4} after {iterations} Gauss–Newton iterations."
        ),
        Finding::DiffDriveMeans {
            output,
            diffusion,
            nominal_end,
            lie_mean,
            cartesian_mean,
            cartesian_mean_stderr,
        } => {
            let coordinate = |k: usize| {
                words::plus_minus(cartesian_mean[k], cartesian_mean_stderr.map(|s| s[k]), 3)
            };
            format!(
                "`{output}` (D = {diffusion}): nominal end ({:.3}, {:.3}); **Lie mean** of the samples ({:.3}, {:.3}); **Cartesian mean** of their positions ({}, {}{}) — it retreats inside the banana.",
                nominal_end[0],
                nominal_end[1],
                lie_mean[0],
                lie_mean[1],
                coordinate(0),
                coordinate(1),
                if cartesian_mean_stderr.is_some() {
                    "; ± its standard error by batch means"
                } else {
                    ""
                }
            )
        }
        Finding::EulerDrift {
            output: _,
            steps,
            dt,
            euler,
            exp,
        } => format!(
            "After {steps} steps of dt = {dt} s: Euler max |RᵗR − I| = **{euler:.3}**; exponential map {exp:.1e}. The Euler frame (the columns of its matrix, drawn as arrows) stretches; the Exp frame stays a rotation."
        ),
        Finding::MethodFailed {
            output,
            step,
            method,
            reason,
            later_steps,
        } => format!(
            "*{} gave no estimate for `{output}`{}{}: {}.*",
            method.label(),
            at(step),
            and_later(*later_steps),
            failure_words(reason)
        ),
        Finding::NotPositiveSemiDefinite {
            output,
            step,
            method,
            smallest_eigenvalue,
            largest_eigenvalue,
            later_steps,
        } => format!(
            "**Warning:** the {} covariance of `{output}`{}{} is not positive semi-definite (smallest eigenvalue {smallest_eigenvalue:.3e}, largest {largest_eigenvalue:.3e}); its regions are drawn from its positive part.",
            method.label(),
            at(step),
            and_later(*later_steps)
        ),
        Finding::SigmaPointsWrap {
            output,
            largest_rotation_rad: turn,
            alpha,
            alpha_below_pi,
        } => format!(
            "**Sigma points wrap around** for `{output}`: one turns {turn:.2} rad, beyond π. Its rotation is the same as a turn of \
             {:.2} rad, so Log brings the point back on the other side and the sigma-point estimate departs from first order \
             (which it equals for compose, between and inverse only while every point stays within π). A smaller α keeps the points \
             inside: any α below {alpha_below_pi:.3} (now {alpha}), e.g. `[methods.sigma_points] alpha = {}`.",
            turn - std::f64::consts::TAU * (turn / std::f64::consts::TAU).round(),
            round_down(*alpha_below_pi)
        ),
        Finding::StepsThinned {
            output,
            steps,
            recorded,
            sampled,
        } => {
            let mut s = format!("`{output}` has {steps} steps: ");
            if recorded <= steps {
                s.push_str(&format!(
                    "{recorded} evenly spaced ones (and the last) are recorded and drawn, to bound memory."
                ));
            } else {
                s.push_str("every one is recorded.");
            }
            if sampled < recorded {
                s.push_str(&format!(
                    " **Monte Carlo at {sampled} of {} steps**: every sample takes every step, and the cloud's statistics (mean, covariance, coverage with their standard errors) are taken at {sampled} evenly spaced steps, the drawn ones and the last, to bound time.",
                    steps + 1
                ));
            }
            s
        }
        Finding::Interrupted => {
            "*Evaluation interrupted: later operations or steps were not evaluated.*".to_owned()
        }
        other => super::graph::finding_text(other).unwrap_or_default(),
    }
}

/// `x` > 0 rounded down to one significant digit (0.907 → 0.9), a value strictly inside a bound.
fn round_down(x: f64) -> f64 {
    let scale = 10f64.powf(-x.log10().floor()); // x · scale ∈ [1, 10)
    let down = (x * scale).floor() / scale;
    if down < x {
        down
    } else {
        ((x * scale * 10.0).floor() - 1.0) / (scale * 10.0)
    }
}

/// " (and at n later steps)", or nothing.
fn and_later(n: u64) -> String {
    match n {
        0 => String::new(),
        1 => " (and at 1 later step)".to_owned(),
        n => format!(" (and at {n} later steps)"),
    }
}

fn tangent_order(kind: GroupKind) -> &'static str {
    match kind {
        GroupKind::So2 => "[θ]",
        GroupKind::So3 => "[θx, θy, θz]",
        GroupKind::Se2 => "[ρx, ρy, θ]",
        GroupKind::Se3 => "[ρx, ρy, ρz, θx, θy, θz]",
    }
}

/// The last step of every node name (or the node itself when static), in first-seen order.
fn final_nodes<G: LieGroup<N>, const N: usize>(e: &Evaluation<G, N>) -> Vec<&Node<G, N>> {
    let mut last: BTreeMap<&str, &Node<G, N>> = BTreeMap::new();
    let mut order = Vec::new();
    for node in &e.nodes {
        if !last.contains_key(node.name.as_str()) {
            order.push(node.name.as_str());
        }
        last.insert(&node.name, node);
    }
    order.iter().filter_map(|n| last.get(n).copied()).collect()
}

/// Why a method failed, in words.
fn failure_words(reason: &FailureReason) -> String {
    match reason {
        FailureReason::NotFinite => "the result is not finite (overflow)".to_owned(),
        FailureReason::StatisticsNotFinite => {
            "the sample statistics are not finite (overflow)".to_owned()
        }
        FailureReason::NeedsOneNoise => {
            "it needs one noise covariance Σ_w shared by every step".to_owned()
        }
        FailureReason::Refused { message } => message.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::round_down;

    #[test]
    fn suggested_alphas_are_short_and_strictly_below_the_bound() {
        for (bound, suggested) in [
            (0.9069, 0.9),
            (0.9, 0.89),
            (3.2, 3.0),
            (0.0347, 0.03),
            (12.5, 10.0),
        ] {
            assert_eq!(round_down(bound), suggested, "{bound}");
            assert!(round_down(bound) < bound);
        }
    }
}
