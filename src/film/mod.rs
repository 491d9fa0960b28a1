//! The film: accumulation of pixel samples and writing of finished images.
pub mod output;
