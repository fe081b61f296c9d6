//! `tss-sim`: the desktop simulator of the tss-reel controller.
//!
//! Exit codes: 0 success; 1 the run failed; 2 a usage error (bad arguments, scenario file,
//! `--set` override or output path), reported before anything is written; 3 a Monte Carlo
//! campaign whose pass rate is below its `--min-pass-rate` (`montecarlo`, `merge`: every output
//! is written).

use std::process::ExitCode;

use clap::{CommandFactory, Parser, Subcommand};
use tss_sim::{analysis, compare, eccentric, montecarlo, run_cmd, scenario, usage};

/// Exit code for usage errors (as clap uses for bad arguments).
const EXIT_USAGE: u8 = 2;
/// Exit code for a run that failed.
const EXIT_FAILURE: u8 = 1;

#[derive(Parser, Debug)]
#[command(
    name = "tss-sim",
    version,
    about = "Desktop simulator of the tss-reel controller (He, Liang & Xu 2011)"
)]
struct Cli {
    /// Print nothing on stdout and draw no progress bar (errors still go to stderr; the files
    /// are written as usual).
    #[arg(long, short, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Simulate a scenario; write history.csv, Figs. 4–6, the Table-1 comparison and a summary.
    Run(run_cmd::RunArgs),
    /// Whole-orbit extent of the equilibrium conditions (Figs. 2–3, Eqs. 9–13).
    Extent(analysis::ExtentArgs),
    /// Characteristic roots, D1, D2 and verdicts at one state (Eqs. 17–19), with an eigenvalue
    /// cross-check.
    Stability(analysis::StabilityArgs),
    /// Monte Carlo campaign: fly the scenario N times with its `[montecarlo]` dispersions (in
    /// parallel, reproducible from the seed), write runs.csv, summary.txt and figures.
    Montecarlo(montecarlo::MonteCarloArgs),
    /// Fly the scenario at each eccentricity; write the keep errors (table, CSV, figure).
    Eccentric(eccentric::EccentricArgs),
    /// Fly several deployment laws (`[controller] law`) on one scenario, and with --runs on the
    /// same dispersed campaign; write one table (compare.txt, compare.csv) and overlaid figures.
    Compare(compare::CompareArgs),
    /// Combine the output directories of `montecarlo --shard K/N` into the whole campaign's.
    Merge(montecarlo::MergeArgs),
    /// Campaigns on a batch system: `campaign slurm` writes (and with --submit submits) a
    /// Monte Carlo campaign as a Slurm job array of shards and a merge job.
    #[command(subcommand)]
    Campaign(CampaignCommand),
    /// Print a shell completion script, e.g. `tss-sim completions bash > tss-sim.bash`.
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Scenario files: `scenario keys` lists every key with its unit, default and rules.
    #[command(subcommand)]
    Scenario(ScenarioCommand),
}

#[derive(Subcommand, Debug)]
enum CampaignCommand {
    /// Write a campaign's Slurm job scripts into DIR: the shards as a job array
    /// (`montecarlo --shard auto`), the merge as a job that runs once every shard succeeded
    /// (`--dependency=afterok`), and submit.sh; with --submit, submit them (docs/campaigns.md).
    Slurm(montecarlo::SlurmArgs),
}

#[derive(Subcommand, Debug)]
enum ScenarioCommand {
    /// Every scenario key with its type, unit, default and the rules validation enforces (read
    /// from the schema and from validation itself).
    Keys {
        /// `text` (a key per line, its rules indented) or `tsv` (one line per key).
        #[arg(long, value_enum, default_value_t = KeysFormat::Text)]
        format: KeysFormat,
    },
}

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum KeysFormat {
    Text,
    Tsv,
}

fn scenario_command(command: &ScenarioCommand) -> anyhow::Result<()> {
    match command {
        ScenarioCommand::Keys { format } => {
            let keys = scenario::keys::keys();
            print!(
                "{}",
                match format {
                    KeysFormat::Text => scenario::keys::render_text(&keys),
                    KeysFormat::Tsv => scenario::keys::render_tsv(&keys),
                }
            );
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    usage::set_quiet(cli.quiet);
    let result = match cli.command {
        Command::Run(args) => run_cmd::run(args),
        Command::Extent(args) => analysis::run_extent(&args),
        Command::Stability(args) => analysis::run_stability(&args),
        Command::Montecarlo(args) => montecarlo::montecarlo(&args),
        Command::Merge(args) => montecarlo::merge(&args),
        Command::Campaign(CampaignCommand::Slurm(args)) => montecarlo::campaign_slurm(&args),
        Command::Eccentric(args) => eccentric::run_eccentric(&args),
        Command::Compare(args) => compare::compare(&args),
        Command::Completions { shell } => {
            clap_complete::generate(
                shell,
                &mut Cli::command(),
                "tss-sim",
                &mut std::io::stdout(),
            );
            Ok(())
        }
        Command::Scenario(command) => scenario_command(&command),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err:#}");
            if usage::is_usage_error(&err) || analysis::is_usage_error(&err) {
                ExitCode::from(EXIT_USAGE)
            } else if montecarlo::is_below_pass_rate(&err) {
                ExitCode::from(montecarlo::EXIT_BELOW_PASS_RATE)
            } else {
                ExitCode::from(EXIT_FAILURE)
            }
        }
    }
}
