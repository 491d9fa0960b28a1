//! `prism compare`: how two EXR images differ, channel by channel, and whether the difference is
//! consistent with their noise.
//!
//! The statistics are [`prism_core::image::compare`]'s; this prints them, and `--diff out.png` writes
//! its false-colour difference image.

use std::path::{Path, PathBuf};

use clap::Args;

use prism_core::error::{Error, ErrorKind, Result};
use prism_core::image::compare::{compare, write_difference_png};
use prism_core::image::{ChannelImage, read_exr};

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The image under test (OpenEXR)
    pub test: PathBuf,
    /// The reference image (OpenEXR), of the same size
    pub reference: PathBuf,
    /// Write the signed difference (test − reference) as a false-colour PNG
    #[arg(long, value_name = "OUT.png")]
    pub diff: Option<PathBuf>,
    /// Channels to compare [default: R,G,B if both images have them, else X,Y,Z, else Y]
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    pub channels: Option<Vec<String>>,
}

fn load(path: &Path) -> Result<ChannelImage> {
    read_exr(path).map_err(|mut e| {
        e.kind = ErrorKind::Input;
        e
    })
}

pub fn run(args: &CompareArgs) -> Result<()> {
    let test = load(&args.test)?;
    let reference = load(&args.reference)?;
    if (test.width, test.height) != (reference.width, reference.height) {
        return Err(Error::usage(format!(
            "\"{}\" is {}×{} pixels but \"{}\" is {}×{}",
            args.test.display(),
            test.width,
            test.height,
            args.reference.display(),
            reference.width,
            reference.height
        ))
        .with_help("compare images rendered at the same resolution and crop"));
    }
    let comparison = compare(&test, &reference, args.channels.as_deref())?;
    println!(
        "test {}  vs  reference {}",
        args.test.display(),
        args.reference.display()
    );
    println!("{comparison}");
    if let Some(path) = &args.diff {
        write_difference_png(&test, &reference, &comparison, path)?;
        println!("difference image: {}", path.display());
    }
    Ok(())
}
