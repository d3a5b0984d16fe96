//! Command-line interface: one module per subcommand.

mod calibrate;
mod common;
mod compensate;
mod demo;
mod demo_real_cell;
mod demo_text;
mod evaluate;
mod export;
mod fk;
pub(crate) mod flags;
mod import;
mod io_plan;
mod iso9283;
mod limits;
mod paper_tables;
mod plan;
mod report;
mod report_meta;
mod robot;
mod shell;
mod simulate;

use clap::{Parser, Subcommand};

/// Kinematic calibration of industrial robots from laser-tracker measurements.
///
/// Units everywhere: millimetres and degrees. Joint values are model joint values (mm for a
/// prismatic joint), or controller axis values in axis1..axisN columns.
#[derive(Parser, Debug)]
#[command(name = "robocal", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Which chain of a URDF robot (`--base-link`, `--tip-link`), for every robot argument.
    #[command(flatten)]
    chain: common::ChainArgs,
}

#[derive(Subcommand, Debug)]
// Each command's arguments are built only when it runs (or for help, completions, man).
#[command(defer = true)]
enum Command {
    /// Robot models: show a preset or a robot file.
    #[command(subcommand)]
    Robot(robot::RobotCmd),
    /// Forward kinematics: the tool position for given joint values.
    Fk(fk::FkArgs),
    /// Simulate a measurement: a true robot measured by a virtual laser tracker.
    Simulate(Box<simulate::SimulateArgs>),
    /// A tracker export and a joint log (as trackers and controllers write them) into a
    /// measurement CSV: formats and units read, points paired with joints by name, order or time.
    Import(import::ImportArgs),
    /// Fit the measurement frame and identify the calibrated parameters (writes a result JSON).
    Calibrate(calibrate::CalibrateArgs),
    /// Error statistics of measured data under the nominal and calibrated models (validation),
    /// or of measured commanded poses against their desired positions (verification).
    Evaluate(evaluate::EvaluateArgs),
    /// Commanded joints that make the real robot reach the nominal positions (compensation).
    Compensate(compensate::CompensateArgs),
    /// The paper's whole experiment in simulation: its tables beside the paper's, a report, and
    /// the files of every step.
    Demo(demo::DemoArgs),
    /// Choose the poses worth measuring: an optimal selection (I-optimal by default, or
    /// D-optimal) from random candidates within the joint limits (and the tracker's range),
    /// compared with random poses.
    Plan(plan::PlanArgs),
    /// ISO 9283 acceptance test: pose accuracy and repeatability (plan the test, evaluate it).
    #[command(subcommand)]
    Iso9283(iso9283::Iso9283Cmd),
    /// The HTML report of a calibration result (tables, histogram, per-point errors, parameters).
    Report(report::ReportArgs),
    /// The calibrated robot of a result as a file for other tools: a URDF (ROS, MoveIt) or a
    /// robocal robot file.
    Export(export::ExportArgs),
    /// Shell completions (bash, zsh, fish, elvish, powershell) on standard output.
    Completions(shell::CompletionsArgs),
    /// The manual page (roff) of robocal or one of its commands on standard output.
    Man(shell::ManArgs),
}

/// Runs a parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    common::set_chain(&cli.chain);
    match cli.command {
        Command::Robot(c) => robot::run(c),
        Command::Fk(a) => fk::run(a),
        Command::Simulate(a) => simulate::run(*a),
        Command::Import(a) => import::run(a),
        Command::Calibrate(a) => calibrate::run(a),
        Command::Evaluate(a) => evaluate::run(a),
        Command::Compensate(a) => compensate::run(a),
        Command::Demo(a) => demo::run(a),
        Command::Plan(a) => plan::run(a),
        Command::Iso9283(c) => iso9283::run(c),
        Command::Report(a) => report::run(a),
        Command::Export(a) => export::run(a),
        Command::Completions(a) => shell::completions(a),
        Command::Man(a) => shell::man(a),
    }
}
