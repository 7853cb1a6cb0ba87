//! What can go wrong reading an arm: each fault names the element and the field.

/// An arm that cannot be built, or a call it cannot answer.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// The file is not well-formed XML, or not a URDF.
    #[error("not XML a URDF reader can take: {0}")]
    Xml(String),
    /// A xacro file (macros unexpanded).
    #[error("a xacro file: expand it first (`xacro robot.urdf.xacro > robot.urdf`)")]
    Xacro,
    /// An element's field is missing or wrong.
    #[error("{at}: {field}: {problem}")]
    Field {
        /// The element, `joint `name``.
        at: String,
        /// The field, `origin xyz`.
        field: String,
        /// What is wrong with it.
        problem: String,
    },
    /// The chain asked for cannot be made from the robot.
    #[error("chain from `{base}` to `{tip}`: {problem}")]
    Chain {
        /// The base link asked for.
        base: String,
        /// The tip link asked for.
        tip: String,
        /// Why not.
        problem: String,
    },
    /// Dynamics of an arm that cannot have them.
    #[error("dynamics: {0}")]
    Dynamics(String),
    /// A call with the wrong number of joint values.
    #[error("{what}: {got} values for an arm of {dof} joints")]
    Length {
        /// Which argument.
        what: &'static str,
        /// Values given.
        got: usize,
        /// Joints of the arm.
        dof: usize,
    },
}
