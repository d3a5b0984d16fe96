//! What the program fuzz targets share: the bytes split into files at 0 bytes, read as UTF-8 (the
//! command refuses other text before reading), compensated on the KUKA preset against itself.

use robocal_core::programs::frames::KrlConfig;
use robocal_core::programs::{compensate_program, Format, ProgramSettings, Source};
use robocal_core::{Compensator, DampedLeastSquares};
use std::path::Path;

/// Compensates the program in `data` (files separated by 0 bytes, named `names`; for KRL the
/// third is a `$config.dat`) and checks what comes back.
pub fn check_program(format: Format, data: &[u8], names: &[&str]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let mut parts = text.splitn(names.len(), '\0');
    let mut sources: Vec<Source> = Vec::new();
    let mut config = None;
    for (k, name) in names.iter().enumerate() {
        let Some(part) = parts.next() else { break };
        if k == 2 {
            // A `$config.dat`: its frames, or an error (then the program is not read).
            match KrlConfig::parse(Path::new(name), part) {
                Ok(c) => config = Some(c),
                Err(_) => return,
            }
        } else {
            sources.push(Source {
                path: Path::new(name).to_owned(),
                text: part.to_owned(),
            });
        }
    }
    // Each file's targets alone: read or refused, never a panic.
    for s in &sources {
        let _ = format.targets(&s.path, &s.text);
    }
    let kuka = robocal_core::preset("kuka-kr480-r3330").expect("preset");
    let solver = DampedLeastSquares {
        max_iterations: 20,
        ..DampedLeastSquares::default()
    };
    let comp = Compensator::new(&kuka, &kuka, solver).expect("same robot");
    let settings = ProgramSettings::default();
    let Ok(out) = compensate_program(&sources, format, config.as_ref(), &comp, &settings) else {
        return;
    };
    assert_eq!(out.texts.len(), sources.len());
    let applied = out.changes.iter().filter(|c| c.applied).count();
    for c in &out.changes {
        assert!(c.file < sources.len());
        assert_eq!(c.old.len(), c.new.len());
        if c.applied {
            assert!(c.new.iter().all(|v| v.is_finite()));
        } else {
            assert_eq!(c.old, c.new);
        }
    }
    // Nothing compensated with a model equal to the nominal one beyond the stored digits: a
    // program whose targets were all left unchanged comes back byte for byte.
    if applied == 0 {
        for (t, s) in out.texts.iter().zip(&sources) {
            assert_eq!(t, &s.text);
        }
    }
    for m in &out.motions {
        assert!(m.motion.line >= 1);
        for k in &m.targets {
            assert!(*k < out.changes.len());
        }
    }
}
