//! What a world that cannot be built says: the field and the problem.

/// A world that cannot be built: the field and the problem, worded as the scenario's
/// own errors are (`tactile check` shows it the same way).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WorldError {
    /// A value (or a file it names) the world cannot take.
    #[error("field `{field}`: {problem}")]
    Invalid {
        /// Dotted path of the field, e.g. `environment.bodies[2].shape.file`.
        field: String,
        /// What is wrong.
        problem: String,
    },
}

pub(crate) fn invalid(field: impl Into<String>, problem: impl Into<String>) -> WorldError {
    WorldError::Invalid {
        field: field.into(),
        problem: problem.into(),
    }
}
