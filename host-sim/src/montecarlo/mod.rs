//! Monte Carlo campaigns (`tss-sim montecarlo`, `tss-sim merge`): the paper mission flown many
//! times with dispersed inputs, judged against declared pass/fail criteria.
//!
//! A scenario declares its campaign in `[montecarlo]` (ignored by `tss-sim run`):
//!
//! ```toml
//! [[montecarlo.dispersion]]
//! field = "initial.delta_rad"   # a number field of the scenario, by the key `--set` takes
//! distribution = "normal"       # "normal" (std, optional mean) or "uniform" (min, max)
//! std = 0.0349                  # mean defaults to the nominal value (file and --set)
//!
//! [[montecarlo.dispersion]]
//! field = "masses.sub_kg"
//! distribution = "uniform"
//! min = -0.1                    # relative = true: value = nominal × (1 + draw)
//! max = 0.1
//! relative = true
//!
//! [montecarlo.criteria]         # every criterion left out is not checked
//! max_keep1_error_m = 0.5       # max |l − stage1.keep_length_m| over keep1_from_s…keep1_until_s
//! no_slack = true
//! ```
//!
//! Run `i` of a campaign with seed `S` draws its inputs from a generator seeded by
//! [`run_seed`]`(S, i, DISPERSION_STREAM)` and flies with `sensors.seed =
//! run_seed(S, i, SENSOR_STREAM)`: a run depends only on the scenario, the seed and its index,
//! never on the thread count or on which shard runs it.
//!
//! On a cluster, `tss-sim campaign slurm` ([`slurm`]) writes the campaign as a Slurm job array
//! of shards (`montecarlo --shard auto`, [`shard`]) and a merge job that runs once every shard
//! has succeeded; each shard journals its runs as they finish ([`journal`]), so a shard that is
//! killed or requeued resumes where it stopped, and `merge` checks that the shards were flown
//! by one build on one scenario. docs/campaigns.md is the guide.

pub mod campaign;
pub mod cmd;
pub mod consistency;
pub mod exact_sum;
pub mod interval;
pub mod journal;
pub mod plots;
pub mod progress;
pub mod shard;
pub mod slurm;
pub mod stats;
pub mod table;

pub use campaign::{run_seed, Campaign, Outcome, RunRecord, DISPERSION_STREAM, SENSOR_STREAM};
pub use cmd::{
    is_below_pass_rate, merge, montecarlo, MergeArgs, MonteCarloArgs, EXIT_BELOW_PASS_RATE,
};
pub use shard::{Shard, ShardSpec};
pub use slurm::{campaign_slurm, SlurmArgs};
