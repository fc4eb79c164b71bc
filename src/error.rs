//! Errors a user can cause with their input. Each names the file and the key so the
//! message alone tells what to fix; the binary turns them into exit code 2.

use std::fmt;

#[derive(Debug, Clone)]
pub struct InputError {
    pub file: String,
    pub key: String,
    pub message: String,
}

impl InputError {
    pub fn new(file: &str, key: &str, message: impl Into<String>) -> Self {
        InputError {
            file: file.to_string(),
            key: key.to_string(),
            message: message.into(),
        }
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.key.is_empty() {
            write!(f, "{}: {}", self.file, self.message)
        } else {
            write!(f, "{}: key `{}`: {}", self.file, self.key, self.message)
        }
    }
}

impl std::error::Error for InputError {}

/// Anything that ends a command: bad input (exit 2), a failed run (exit 1) or a
/// missing device.
#[derive(Debug)]
pub enum SpatterError {
    Input(InputError),
    Runtime(String),
}

impl From<InputError> for SpatterError {
    fn from(e: InputError) -> Self {
        SpatterError::Input(e)
    }
}

impl fmt::Display for SpatterError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SpatterError::Input(e) => write!(f, "{e}"),
            SpatterError::Runtime(m) => write!(f, "{m}"),
        }
    }
}

impl std::error::Error for SpatterError {}
