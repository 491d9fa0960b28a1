//! `prism plugins`: the plugins Prism reads from scene files, by class; with `--markdown`, the
//! full reference with every parameter (the source of docs/plugins.md).

use clap::Args;

use prism_core::error::Result;
use prism_mitsuba::reference::{plugins_markdown, reference};

#[derive(Args, Debug)]
pub struct PluginsArgs {
    /// Only this class (integrator, sensor, film, rfilter, sampler, shape, bsdf, texture,
    /// emitter, spectrum), with each plugin's parameters
    pub class: Option<String>,
    /// Print the full reference in Markdown (docs/plugins.md is this output)
    #[arg(long)]
    pub markdown: bool,
}

pub fn run(args: &PluginsArgs) -> Result<()> {
    if args.markdown {
        print!("{}", plugins_markdown());
        return Ok(());
    }
    let classes = reference();
    let Some(wanted) = &args.class else {
        for class in &classes {
            let names: Vec<&str> = class.plugins.iter().map(|p| p.name).collect();
            println!("{:<11} {}", class.class.tag(), names.join(", "));
        }
        println!(
            "\n`prism plugins CLASS` lists a class's parameters; docs/plugins.md has them all."
        );
        return Ok(());
    };
    let Some(class) = classes.iter().find(|c| c.class.tag() == wanted) else {
        let tags: Vec<&str> = classes.iter().map(|c| c.class.tag()).collect();
        return Err(
            prism_core::error::Error::usage(format!("no plugin class \"{wanted}\""))
                .with_help(format!("classes: {}", tags.join(", "))),
        );
    };
    for plugin in &class.plugins {
        println!(
            "{} \"{}\" ({}): {}",
            class.class.tag(),
            plugin.name,
            plugin.origin.label(),
            plugin.summary
        );
        for p in plugin.params {
            println!("    {:<24} {}", p.name, p.doc);
        }
        println!();
    }
    Ok(())
}
