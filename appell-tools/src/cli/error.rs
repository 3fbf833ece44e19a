//! [`CliError`]: why the command line failed.

use appell_core::ModelError;
use std::error::Error;

/// Why the command line failed.
#[derive(Debug)]
pub enum CliError {
    /// Unknown subcommand or unexpected arguments; holds the usage text.
    Usage(String),
    /// Reading stdin or writing stdout failed.
    Io(std::io::Error),
    /// The model could not report its parameters.
    Model(ModelError),
    /// `bench` found no state where both the rhs and the oracle succeed.
    Bench(String),
    /// `accuracy` could not read its problem or compute the reference.
    Accuracy(String),
    /// `animate` could not read its problem or simulate it.
    Animate(String),
    /// The example's default action failed.
    Action(Box<dyn Error>),
}

impl core::fmt::Display for CliError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            CliError::Usage(usage) => write!(f, "{usage}"),
            CliError::Io(e) => write!(f, "i/o error: {e}"),
            CliError::Model(e) => write!(f, "{e}"),
            CliError::Bench(why) => write!(f, "bench: {why}"),
            CliError::Accuracy(why) => write!(f, "accuracy: {why}"),
            CliError::Animate(why) => write!(f, "animate: {why}"),
            CliError::Action(e) => write!(f, "{e}"),
        }
    }
}

impl Error for CliError {
    fn source(&self) -> Option<&(dyn Error + 'static)> {
        match self {
            CliError::Io(e) => Some(e),
            CliError::Model(e) => Some(e),
            CliError::Action(e) => Some(e.as_ref()),
            CliError::Usage(_)
            | CliError::Bench(_)
            | CliError::Accuracy(_)
            | CliError::Animate(_) => None,
        }
    }
}

impl From<std::io::Error> for CliError {
    fn from(e: std::io::Error) -> Self {
        CliError::Io(e)
    }
}

impl From<ModelError> for CliError {
    fn from(e: ModelError) -> Self {
        CliError::Model(e)
    }
}
