//! Settings resolved once: each value from the command line, else the file, else the
//! default, and each stage gets only its own ([`EvalSettings`], [`DrawSettings`]).

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use crate::draw::DrawSettings;
use crate::eval::EvalSettings;
use crate::input::Input;
use crate::plan::{StepPolicy, limits};

/// Monte Carlo samples when neither the command line nor the file says.
pub const DEFAULT_SAMPLES: u64 = crate::eval::DEFAULT_SAMPLES as u64;
/// Probability inside drawn regions when neither the command line nor the file says.
pub const DEFAULT_CONFIDENCE: f64 = 0.95;

/// Values given on the command line (or by any other front end), overriding the file's.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Overrides {
    /// `--seed`.
    pub seed: Option<u64>,
    /// `--samples`.
    pub samples: Option<u64>,
    /// `--confidence`.
    pub confidence: Option<f64>,
    /// `--block-samples`.
    pub block_samples: Option<u64>,
    /// `--topic` (repeatable; robot logs only): the topics to read.
    pub topics: Vec<String>,
    /// `--every N` (robot logs only): draw every N-th message.
    pub every: Option<u64>,
    /// Which steps of long propagations are kept (no flag: live mode's quick preview thins
    /// them); `None`: [`StepPolicy::default`].
    pub steps: Option<StepPolicy>,
}

/// A command-line value out of range: names the flag, the value and what is accepted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{flag} {value}: out of range: {expected}")]
pub struct SettingsError {
    /// The flag, e.g. `--samples`.
    pub flag: &'static str,
    /// The value given.
    pub value: String,
    /// What is accepted.
    pub expected: String,
}

/// Everything the stages need, resolved.
#[derive(Debug, Clone)]
pub struct Settings {
    /// For [`crate::eval::evaluate`].
    pub eval: EvalSettings,
    /// For [`crate::draw::scene`].
    pub draw: DrawSettings,
}

/// `--confidence` must be a probability strictly between 0 and 1 (every input's check).
pub(super) fn check_confidence(confidence: Option<f64>) -> Result<(), SettingsError> {
    match confidence {
        Some(p) if !(p > 0.0 && p < 1.0) => Err(SettingsError {
            flag: "--confidence",
            value: p.to_string(),
            expected: "a probability strictly between 0 and 1, e.g. 0.95".to_owned(),
        }),
        _ => Ok(()),
    }
}

/// Resolves the settings of `input` under `overrides` (values in the file were checked when
/// it was read; flags are checked here and named in errors).
///
/// ```
/// use posecov::app::{Overrides, load, resolve};
/// let loaded = load("camera_on_robot").unwrap();
/// let e = resolve(&loaded.input, &Overrides { samples: Some(1), ..Default::default() }, None).unwrap_err();
/// assert_eq!(e.to_string(), "--samples 1: out of range: use 2 ..= 10000000");
/// let s = resolve(&loaded.input, &Overrides { seed: Some(9), ..Default::default() }, None).unwrap();
/// assert_eq!(s.eval.seed, 9);
/// ```
pub fn resolve(
    input: &Input,
    overrides: &Overrides,
    cancel: Option<Arc<AtomicBool>>,
) -> Result<Settings, SettingsError> {
    let file = &input.defaults;
    if let Some(flag) = (!overrides.topics.is_empty())
        .then_some("--topic")
        .or(overrides.every.map(|_| "--every"))
    {
        return Err(SettingsError {
            flag,
            value: overrides
                .topics
                .first()
                .cloned()
                .unwrap_or_else(|| overrides.every.map_or_else(String::new, |n| n.to_string())),
            expected: "a robot log (ROS 1 bag or MCAP file); this input is not one".to_owned(),
        });
    }
    if let Some(n) = overrides.samples
        && !(limits::MIN_SAMPLES..=limits::MAX_SAMPLES).contains(&n)
    {
        return Err(SettingsError {
            flag: "--samples",
            value: n.to_string(),
            expected: format!("use {} ..= {}", limits::MIN_SAMPLES, limits::MAX_SAMPLES),
        });
    }
    check_confidence(overrides.confidence)?;
    if let Some(b) = overrides.block_samples
        && !(1..=limits::MAX_SAMPLES).contains(&b)
    {
        return Err(SettingsError {
            flag: "--block-samples",
            value: b.to_string(),
            expected: format!("use 1 ..= {}", limits::MAX_SAMPLES),
        });
    }
    let samples = overrides
        .samples
        .or(file.samples)
        .unwrap_or(DEFAULT_SAMPLES);
    let confidence = overrides
        .confidence
        .or(file.confidence)
        .unwrap_or(DEFAULT_CONFIDENCE);
    let steps = overrides.steps.unwrap_or_default();
    Ok(Settings {
        eval: EvalSettings {
            seed: overrides.seed.or(file.seed).unwrap_or(0),
            samples: samples as usize,
            methods: file.methods.clone(),
            block_samples: overrides.block_samples.map(|b| b as usize),
            steps,
            unscented: file.sigma_points.unwrap_or_default(),
            cancel,
        },
        draw: DrawSettings {
            about: input.about.clone(),
            confidence,
            choices: input.draw.clone(),
            steps,
        },
    })
}
