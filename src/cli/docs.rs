//! `lodeval completions SHELL` and `lodeval man`: shell completions (clap_complete) and manual
//! pages (clap_mangen) generated from the same clap definitions as the parser, so they never
//! drift from the flags.

use std::path::PathBuf;

use clap::{Args, CommandFactory};
use lodeval::Error;

use super::print::emit;

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval completions bash > ~/.local/share/bash-completion/completions/lodeval\n\n\
    Exit codes: 0 written · 2 usage"
)]
pub(crate) struct CompletionsArgs {
    /// The shell: bash, zsh, fish, elvish or powershell.
    pub(crate) shell: clap_complete::Shell,
}

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval man --out-dir man/ && man man/lodeval.1\n\n\
    Exit codes: 0 written · 2 the folder cannot be written"
)]
pub(crate) struct ManArgs {
    /// Write lodeval.1 and one page per command (lodeval-eval.1, ...) into this folder instead
    /// of printing lodeval.1.
    #[arg(long)]
    pub(crate) out_dir: Option<PathBuf>,
}

/// Print the completion script.
pub(crate) fn completions(a: CompletionsArgs) -> Result<(), Error> {
    let mut cmd = super::Cli::command();
    let mut buf = Vec::new();
    clap_complete::generate(a.shell, &mut cmd, "lodeval", &mut buf);
    emit(&String::from_utf8_lossy(&buf))
}

/// Render one page.
fn page(cmd: clap::Command) -> Result<Vec<u8>, Error> {
    let mut buf = Vec::new();
    clap_mangen::Man::new(cmd)
        .render(&mut buf)
        .map_err(|e| Error::Internal(format!("man page: {e}")))?;
    Ok(buf)
}

/// Print or write the manual pages.
pub(crate) fn man(a: ManArgs) -> Result<(), Error> {
    let cmd = super::Cli::command();
    let Some(dir) = a.out_dir else {
        return emit(&String::from_utf8_lossy(&page(cmd)?));
    };
    std::fs::create_dir_all(&dir).map_err(|e| {
        Error::input(
            &dir,
            format!("cannot create the folder: {e}"),
            "give an --out-dir you can write to",
        )
    })?;
    lodeval::io::write_atomic(&dir.join("lodeval.1"), &page(cmd.clone())?)?;
    for sub in cmd.get_subcommands() {
        let name = format!("lodeval-{}", sub.get_name());
        let sub = sub.clone().name(name.clone());
        lodeval::io::write_atomic(&dir.join(format!("{name}.1")), &page(sub)?)?;
    }
    emit(&format!("wrote {}\n", dir.display()))
}
