//! `robocal completions SHELL` and `robocal man [COMMAND]`: shell completions and manual pages,
//! generated from the same clap definitions that `--help` prints (clap_complete, clap_mangen),
//! so they cannot describe a flag the program does not have.

use crate::exit;
use clap::{Args, CommandFactory};
use std::io::Write;

#[derive(Args, Debug)]
pub struct CompletionsArgs {
    /// The shell to complete for. Bash: `robocal completions bash >
    /// ~/.local/share/bash-completion/completions/robocal`; zsh: a file `_robocal` in a directory
    /// of `$fpath`; fish: `~/.config/fish/completions/robocal.fish`.
    #[arg(value_enum, value_name = "SHELL")]
    shell: clap_complete::Shell,
}

#[derive(Args, Debug)]
pub struct ManArgs {
    /// The command whose page to print (e.g. `calibrate`, `robot show`) [default: robocal's own
    /// page, which lists the commands]. View with `robocal man | man -l -`.
    #[arg(value_name = "COMMAND", num_args = 0..)]
    command: Vec<String>,
}

/// Prints the completion script of `shell` to standard output.
pub fn completions(a: CompletionsArgs) -> anyhow::Result<()> {
    let mut cmd = super::Cli::command();
    let mut out = Vec::new();
    clap_complete::generate(a.shell, &mut cmd, "robocal", &mut out);
    write_stdout(&out)
}

/// Prints the manual page (roff) of robocal or of one of its commands to standard output.
pub fn man(a: ManArgs) -> anyhow::Result<()> {
    let mut cmd = super::Cli::command();
    cmd.build();
    let mut name = String::from("robocal");
    for part in &a.command {
        let Some(sub) = cmd.find_subcommand(part).cloned() else {
            let known: Vec<&str> = cmd.get_subcommands().map(|s| s.get_name()).collect();
            return Err(exit::usage(format!(
                "`{name} {part}` is not a command; the commands of `{name}`: {}",
                if known.is_empty() {
                    "none".to_owned()
                } else {
                    known.join(", ")
                }
            )));
        };
        name = format!("{name}-{}", sub.get_name());
        cmd = sub;
    }
    let mut out = Vec::new();
    clap_mangen::Man::new(cmd)
        .title(name.to_uppercase())
        .section("1")
        .source(concat!("robocal ", env!("CARGO_PKG_VERSION")))
        .manual("robocal manual")
        .render(&mut out)
        .map_err(|e| anyhow::anyhow!("rendering the manual page: {e}"))?;
    write_stdout(&out)
}

fn write_stdout(bytes: &[u8]) -> anyhow::Result<()> {
    let mut so = std::io::stdout().lock();
    so.write_all(bytes)
        .and_then(|_| so.flush())
        .map_err(|e| anyhow::Error::new(e).context("writing to standard output"))
}
