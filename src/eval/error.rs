//! Why a plan could not be evaluated ([`EvalError`]), its place (the operation) kept as data.

/// Why a plan could not be evaluated. `operation` is the index of the operation in the plan
/// (`operation[k]` in a scenario file), `output` the name it defines.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EvalError {
    /// A pose graph that cannot be solved here (too large, or the linear algebra failed).
    #[error("pose graph: {0}")]
    Graph(String),
    /// A setting is out of range (the caller validates its own flags first).
    #[error("{what} = {value} is out of range: {expected}")]
    Setting {
        /// Which setting.
        what: &'static str,
        /// Its value.
        value: String,
        /// What is accepted.
        expected: String,
    },
    /// An input pose cannot be sampled (its covariance has no square root).
    #[error("pose `{pose}`: {source}")]
    Pose {
        /// The pose's name.
        pose: String,
        /// The library's error.
        source: crate::Error,
    },
    /// An operand refers to a definition that does not exist yet, or is not a pose.
    #[error("operation[{operation}] {}", self.without_place())]
    Undefined {
        /// Operation index.
        operation: usize,
        /// Its output.
        output: String,
        /// The definition referred to.
        definition: usize,
    },
    /// An operation that the plan's group cannot do.
    #[error("operation[{operation}] {}", self.without_place())]
    WrongGroup {
        /// Operation index.
        operation: usize,
        /// Its output.
        output: String,
        /// The operation.
        what: &'static str,
        /// The group.
        group: &'static str,
    },
    /// The work asked for exceeds [`limits::MAX_PARTICLE_STEPS`](crate::plan::limits::MAX_PARTICLE_STEPS).
    #[error("operation[{operation}] {}", self.without_place())]
    TooMuchWork {
        /// Operation index (where the limit is crossed).
        operation: usize,
        /// Its output.
        output: String,
        /// Samples.
        samples: usize,
        /// Steps of that operation.
        steps: u64,
        /// Particle-steps of the whole plan.
        work: f64,
        /// The limit.
        limit: f64,
    },
    /// The result is not finite: an input too large, a noise too strong, a parameter too small.
    #[error("operation[{operation}] {}", self.without_place())]
    NonFinite {
        /// Operation index.
        operation: usize,
        /// Its output.
        output: String,
        /// Step, for propagations.
        step: Option<u64>,
        /// The method whose result overflowed.
        method: &'static str,
    },
    /// Fusion failed; `input` is the position in `inputs` of the estimate at fault, if one is.
    #[error("operation[{operation}] {}", self.without_place())]
    Fusion {
        /// Operation index.
        operation: usize,
        /// Its output.
        output: String,
        /// The estimate at fault.
        input: Option<usize>,
        /// The library's error.
        source: crate::Error,
    },
    /// The library refused (e.g. an invalid robot, a singular joint covariance).
    #[error("operation[{operation}] {}", self.without_place())]
    Math {
        /// Operation index.
        operation: usize,
        /// Its output.
        output: String,
        /// The library's error.
        source: crate::Error,
    },
}

impl EvalError {
    /// The message without its place (`operation[i] `): what a located error says after the
    /// file's own place for that operation (the app's `Loaded::locate`). Errors of no
    /// operation are their whole message.
    ///
    /// ```
    /// use posecov::eval::EvalError;
    /// let e = EvalError::Undefined { operation: 2, output: "x".into(), definition: 9 };
    /// assert_eq!(e.without_place(), "(`x`): operand 9 is not an earlier pose");
    /// assert_eq!(e.to_string(), "operation[2] (`x`): operand 9 is not an earlier pose");
    /// ```
    pub fn without_place(&self) -> String {
        match self {
            EvalError::Setting { .. } | EvalError::Pose { .. } | EvalError::Graph(_) => {
                self.to_string()
            }
            EvalError::Undefined {
                output, definition, ..
            } => format!("(`{output}`): operand {definition} is not an earlier pose"),
            EvalError::WrongGroup {
                output,
                what,
                group,
                ..
            } => format!("(`{output}`): {what} is not available for {group}"),
            EvalError::TooMuchWork {
                output,
                samples,
                steps,
                work,
                limit,
                ..
            } => format!(
                "(`{output}`): {samples} samples × {steps} steps = {work:.2e} particle-steps in all exceeds the limit {limit:.0e}; lower the samples or the steps"
            ),
            EvalError::NonFinite {
                output,
                step,
                method,
                ..
            } => format!(
                "(`{output}`{}): the {method} result is not finite (overflow); check the magnitudes of its inputs and parameters",
                step.map_or(String::new(), |k| format!(", step {k}"))
            ),
            EvalError::Fusion {
                output,
                input,
                source,
                ..
            } => format!(
                "(`{output}`): fusion failed{}: {source}",
                input.map_or(String::new(), |i| format!(" at inputs[{i}]"))
            ),
            EvalError::Math { output, source, .. } => format!("(`{output}`): {source}"),
        }
    }

    /// The index of the operation the error is about, if any.
    ///
    /// ```
    /// use posecov::eval::EvalError;
    /// let e = EvalError::Undefined { operation: 2, output: "x".into(), definition: 9 };
    /// assert_eq!(e.operation(), Some(2));
    /// ```
    pub fn operation(&self) -> Option<usize> {
        match self {
            EvalError::Setting { .. } | EvalError::Pose { .. } | EvalError::Graph(_) => None,
            EvalError::Undefined { operation, .. }
            | EvalError::WrongGroup { operation, .. }
            | EvalError::TooMuchWork { operation, .. }
            | EvalError::NonFinite { operation, .. }
            | EvalError::Fusion { operation, .. }
            | EvalError::Math { operation, .. } => Some(*operation),
        }
    }
}
