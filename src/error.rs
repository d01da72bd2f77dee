//! One error type for everything a user can get wrong or the system can
//! refuse; each says where (file, option) and what.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{path}: unknown output extension (use .exr, .png or .ppm)")]
    UnknownExtension { path: PathBuf },
    #[error("{path}: cannot write image: {message}")]
    Encode { path: PathBuf, message: String },
    #[error("{path}: cannot read image: {message}")]
    Decode { path: PathBuf, message: String },
    #[error("{0}")]
    Invalid(String),
}

pub type Result<T> = std::result::Result<T, Error>;
