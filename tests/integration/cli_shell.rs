//! `robocal completions SHELL` and `robocal man [COMMAND]`: generated from the CLI's own
//! definitions, so they name every command and flag the program has.

use crate::util::*;

#[test]
fn completions_name_the_commands_and_flags() {
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let o = ok(&["completions", shell]);
        let s = o.stdout();
        for word in ["calibrate", "report", "--validate", "--out"] {
            assert!(s.contains(word), "{shell} completions lack {word}");
        }
    }
    // bash: the script defines its function and registers it for robocal.
    let s = ok(&["completions", "bash"]).stdout();
    assert!(
        s.contains("complete -F _robocal") && s.contains("robocal"),
        "{s}"
    );
    robocal(&["completions", "tcsh"]).assert_code(2);
}

#[test]
fn man_pages_for_robocal_and_each_command() {
    let top = ok(&["man"]).stdout();
    assert!(top.contains(".TH ROBOCAL 1"), "{top}");
    for cmd in ["calibrate", "evaluate", "compensate", "report", "simulate"] {
        assert!(top.contains(cmd), "the top page does not list {cmd}");
        let page = ok(&["man", cmd]).stdout();
        assert!(
            page.contains(&format!(".TH ROBOCAL-{} 1", cmd.to_uppercase())),
            "{page}"
        );
        assert!(page.contains(".SH OPTIONS"), "{cmd}: {page}");
    }
    let show = ok(&["man", "robot", "show"]).stdout();
    assert!(show.contains("ROBOCAL-ROBOT-SHOW") && show.contains("params"));
    let o = robocal(&["man", "calibrat"]);
    o.assert_code(2);
    assert!(o.stderr().contains("not a command") && o.stderr().contains("calibrate"));
}
