//! What a command reads and writes, checked before any work: no output may be one of the inputs
//! (the same path, a symbolic link to it or the same file through a hard link) or another
//! output, and every output must be a regular file or a new one (see
//! [`robocal_core::io::resolve_output`]). `-` is standard output where a command accepts it.

use crate::exit;
use anyhow::Context;
use robocal_core::io::AtomicFile;
use std::path::{Path, PathBuf};

/// The name of standard output as an output argument.
pub const STDOUT: &str = "-";

/// An output argument as messages show it: `standard output` for `-`.
pub fn shown(path: &Path) -> String {
    if path.as_os_str() == STDOUT {
        "standard output".to_owned()
    } else {
        path.display().to_string()
    }
}

/// The inputs and outputs of one command, as its validated flags give them.
#[derive(Default)]
pub struct IoPlan {
    inputs: Vec<Input>,
    outputs: Vec<Output>,
}

/// An input file and how to name it in messages (`--joints j.csv`).
struct Input {
    path: PathBuf,
    described: String,
}

/// An output file.
struct Output {
    /// The flag that names it (`--out`).
    flag: String,
    /// The argument of the flag (a file, or the directory for files written into one).
    given: PathBuf,
    /// The file written, when it is not `given` itself: (path, what it is in words).
    derived: Option<(PathBuf, String)>,
    /// `given` is a directory created if needed.
    in_dir: bool,
    /// Why `-` cannot mean standard output here; `None` where it can.
    no_stdout: Option<String>,
}

impl Output {
    fn file(&self) -> &Path {
        self.derived.as_ref().map_or(&self.given, |d| &d.0)
    }

    /// How a message names the file: "--out a.csv: this", "--out a.csv: the truth file ...".
    fn subject(&self) -> String {
        match &self.derived {
            None => format!("{} {}: this", self.flag, self.given.display()),
            Some((p, what)) => format!(
                "{} {}: {what}, {},",
                self.flag,
                self.given.display(),
                p.display()
            ),
        }
    }
}

/// Whether a robot argument names a file (not a built-in preset).
fn robot_file(arg: &str) -> Option<&Path> {
    (!robocal_core::PRESETS.contains(&arg)).then(|| Path::new(arg))
}

impl IoPlan {
    /// An empty plan.
    pub fn new() -> IoPlan {
        IoPlan::default()
    }

    /// An input file named by `flag`.
    pub fn input(&mut self, flag: &str, path: &Path) -> &mut Self {
        self.inputs.push(Input {
            path: path.to_owned(),
            described: format!("{flag} {}", path.display()),
        });
        self
    }

    /// An optional input file.
    pub fn input_opt(&mut self, flag: &str, path: Option<&Path>) -> &mut Self {
        if let Some(p) = path {
            self.input(flag, p);
        }
        self
    }

    /// A robot argument (`--robot NAME|FILE`): an input when it is a file.
    pub fn robot(&mut self, flag: &str, arg: &str) -> &mut Self {
        if let Some(p) = robot_file(arg) {
            self.input(flag, p);
        }
        self
    }

    /// An optional robot argument.
    pub fn robot_opt(&mut self, flag: &str, arg: Option<&str>) -> &mut Self {
        if let Some(a) = arg {
            self.robot(flag, a);
        }
        self
    }

    /// The files a calibration result records (its measurement files and robot file, as
    /// `robocal calibrate` was given them), which later commands read by default: they are
    /// protected like inputs. A result that cannot be read records nothing here (reading it
    /// properly reports the problem).
    pub fn recorded_in(&mut self, flag: &str, result: &Path) -> &mut Self {
        #[derive(serde::Deserialize)]
        struct Recorded {
            settings: Option<robocal_core::io::result_sections::Settings>,
        }
        let Some(settings) = std::fs::read_to_string(result)
            .ok()
            .and_then(|t| serde_json::from_str::<Recorded>(&t).ok())
            .and_then(|r| r.settings)
        else {
            return self;
        };
        for (file, what) in [
            (&settings.data, "the calibration data"),
            (&settings.validate, "the validation data"),
        ] {
            if let Some(p) = file {
                self.inputs.push(Input {
                    path: PathBuf::from(p),
                    described: format!("{p}, {what} recorded in {flag} {}", result.display()),
                });
            }
        }
        if let Some(p) = settings.robot_arg.as_deref().and_then(robot_file) {
            self.inputs.push(Input {
                path: p.to_owned(),
                described: format!(
                    "{}, the robot file recorded in {flag} {}",
                    p.display(),
                    result.display()
                ),
            });
        }
        self
    }

    /// An output file that cannot be standard output (`no_stdout` says why, for the message).
    pub fn output(&mut self, flag: &str, path: &Path, no_stdout: &str) -> &mut Self {
        self.outputs.push(Output {
            flag: flag.to_owned(),
            given: path.to_owned(),
            derived: None,
            in_dir: false,
            no_stdout: Some(no_stdout.to_owned()),
        });
        self
    }

    /// An output file, or standard output for `-`.
    pub fn output_or_stdout(&mut self, flag: &str, path: &Path) -> &mut Self {
        self.outputs.push(Output {
            flag: flag.to_owned(),
            given: path.to_owned(),
            derived: None,
            in_dir: false,
            no_stdout: None,
        });
        self
    }

    /// A file written beside the output of `flag` (e.g. the truth file beside `--out`), `what`
    /// it is in words.
    pub fn derived_output(
        &mut self,
        flag: &str,
        given: &Path,
        file: &Path,
        what: &str,
    ) -> &mut Self {
        self.outputs.push(Output {
            flag: flag.to_owned(),
            given: given.to_owned(),
            derived: Some((file.to_owned(), what.to_owned())),
            in_dir: false,
            no_stdout: Some(String::new()),
        });
        self
    }

    /// Files `names` written into the directory `dir` of `flag` (created if needed).
    pub fn output_dir(&mut self, flag: &str, dir: &Path, names: &[&str]) -> &mut Self {
        for name in names {
            self.outputs.push(Output {
                flag: flag.to_owned(),
                given: dir.to_owned(),
                derived: Some((dir.join(name), "the file written into it".to_owned())),
                in_dir: true,
                no_stdout: Some(String::new()),
            });
        }
        self
    }

    /// Checks the plan (before any work): a usage error (exit 2) for an output that is an input
    /// or another output, or `-` where standard output is not accepted; an I/O error (exit 4)
    /// for an output that cannot be written (missing directory, a directory, device, FIFO or
    /// socket). Gives the outputs, with standard output taken for the data if one is `-`.
    pub fn check(&self) -> anyhow::Result<Outputs> {
        let mut written: Vec<(&Output, Identity)> = Vec::new();
        let mut stdout = false;
        for o in &self.outputs {
            if o.given.as_os_str() == STDOUT && !o.in_dir {
                match &o.no_stdout {
                    None if stdout => {
                        return Err(exit::usage(format!(
                            "{} -: standard output already takes another output",
                            o.flag
                        )))
                    }
                    None => {
                        stdout = true;
                        continue;
                    }
                    Some(why) => {
                        return Err(exit::usage(format!(
                            "{} -: standard output is not accepted here{}{why}; to write a \
                             file named `-`, give ./-",
                            o.flag,
                            if why.is_empty() { "" } else { ": " }
                        )))
                    }
                }
            }
            let file = writable(o).with_context(|| o.flag.clone())?;
            let id = identity(&file);
            if let Some(i) = self.inputs.iter().find(|i| identity(&i.path) == id) {
                return Err(exit::usage(format!(
                    "{} is also an input ({}{}); write the output to another file",
                    o.subject(),
                    i.described,
                    relation(o.file(), &i.path)
                )));
            }
            if let Some((other, _)) = written.iter().find(|(_, w)| *w == id) {
                return Err(exit::usage(format!(
                    "{} is the same file as {} {}; give each output its own file",
                    o.subject(),
                    other.flag,
                    other.file().display()
                )));
            }
            written.push((o, id));
        }
        // Claimed before any work: a second run writing the same outputs is refused now.
        let files: Vec<&Path> = written.iter().map(|(o, _)| o.file()).collect();
        robocal_core::io::claim_outputs(&files)?;
        let stdout = if stdout {
            Some(claim_stdout().map_err(|e| {
                anyhow::Error::from(robocal_core::Error::Io {
                    path: PathBuf::from("standard output"),
                    source: e,
                })
            })?)
        } else {
            None
        };
        Ok(Outputs { stdout })
    }
}

/// The file an output goes to, checked: for a file in a directory that does not exist yet, the
/// path itself (the directory is created when written).
fn writable(o: &Output) -> robocal_core::Result<PathBuf> {
    if o.in_dir {
        if o.given.exists() && !o.given.is_dir() {
            return Err(robocal_core::Error::Io {
                path: o.given.clone(),
                source: std::io::Error::other("exists and is not a directory"),
            });
        }
        if !o.given.is_dir() {
            return Ok(o.file().to_owned());
        }
    }
    robocal_core::io::resolve_output(o.file())
}

/// What makes two paths the same file.
#[derive(PartialEq, Debug)]
enum Identity {
    /// An existing file: its device and inode (hard links and symbolic links included).
    #[cfg(unix)]
    Node(u64, u64),
    /// Otherwise its absolute path, its directory's links resolved.
    Path(PathBuf),
}

fn identity(p: &Path) -> Identity {
    #[cfg(unix)]
    if let Ok(m) = std::fs::metadata(p) {
        use std::os::unix::fs::MetadataExt;
        return Identity::Node(m.dev(), m.ino());
    }
    if let Ok(c) = std::fs::canonicalize(p) {
        return Identity::Path(c);
    }
    let dir = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match (std::fs::canonicalize(dir), p.file_name()) {
        (Ok(d), Some(n)) => Identity::Path(d.join(n)),
        _ => Identity::Path(p.to_owned()),
    }
}

/// Whether two paths name the same file (same device and inode, through any link), or the same
/// place when they do not exist yet.
pub fn same_file(a: &Path, b: &Path) -> bool {
    identity(a) == identity(b)
}

/// How an output reaches an input it collides with, for the message.
fn relation(out: &Path, input: &Path) -> &'static str {
    if std::fs::symlink_metadata(out).is_ok_and(|m| m.file_type().is_symlink()) {
        return "; reached through a symbolic link";
    }
    match (std::fs::canonicalize(out), std::fs::canonicalize(input)) {
        (Ok(a), Ok(b)) if a != b => "; the same file through a hard link",
        _ => "",
    }
}

/// The outputs of a checked plan.
pub struct Outputs {
    /// The real standard output, when `-` took it for data.
    stdout: Option<std::fs::File>,
}

impl Outputs {
    /// Starts writing the output `path` of the plan: standard output for `-` where the plan
    /// accepted it, else the file (atomically).
    pub fn open(&mut self, path: &Path) -> anyhow::Result<AtomicFile> {
        if path.as_os_str() == STDOUT {
            if let Some(f) = self.stdout.take() {
                return Ok(AtomicFile::stream(
                    Path::new("standard output"),
                    Box::new(f),
                )?);
            }
        }
        Ok(AtomicFile::create(path)?)
    }
}

/// Standard output for data. The command's own messages (summaries, notes) go to standard error
/// from then on, so that the data stream stays clean: the real standard output is duplicated
/// for the data and descriptor 1 is pointed at standard error, which redirects every print of
/// the command at once instead of threading a writer through all of them.
#[cfg(unix)]
fn claim_stdout() -> std::io::Result<std::fs::File> {
    use std::io::Write;
    use std::os::fd::FromRawFd;
    std::io::stdout().flush()?;
    // SAFETY: plain descriptor calls; the new descriptor is owned by the File made from it.
    unsafe {
        let data = libc::fcntl(1, libc::F_DUPFD_CLOEXEC, 3);
        if data < 0 {
            return Err(std::io::Error::last_os_error());
        }
        if libc::dup2(2, 1) < 0 {
            let e = std::io::Error::last_os_error();
            libc::close(data);
            return Err(e);
        }
        Ok(std::fs::File::from_raw_fd(data))
    }
}

#[cfg(not(unix))]
fn claim_stdout() -> std::io::Result<std::fs::File> {
    Err(std::io::Error::other(
        "`-` (standard output) as an output needs a Unix system; give a file",
    ))
}
