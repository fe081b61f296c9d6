//! Which runs of a campaign one process flies: `--shard K/N`, or `--shard auto` from a batch
//! system's environment.
//!
//! Shard K of N flies the runs i with i mod N = K − 1 (K is 1-based). `--shard auto` reads K and
//! N where a batch system puts them:
//!
//! - a Slurm job array (`sbatch --array=MIN-MAX[:STEP]`): task `SLURM_ARRAY_TASK_ID` is shard
//!   (ID − MIN)/STEP + 1 of `SLURM_ARRAY_TASK_COUNT`, whatever MIN is (`--array=0-7` and
//!   `--array=1-8` both make shards 1/8 … 8/8); an array given as a list (`--array=1,3,8`),
//!   whose tasks are not a range, is refused;
//! - a Kubernetes indexed job (`completionMode: Indexed`): `JOB_COMPLETION_INDEX` (0-based) is
//!   shard index + 1, of the N given as `--shard auto/N` (the job's `completions`: Kubernetes
//!   does not put it in the environment).
//!
//! `--shard auto/N` with a Slurm array checks that the array has N tasks.

use std::fmt;

/// Which runs a shard flies: i with i mod count = index − 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// K, 1-based.
    pub index: u64,
    /// N, the number of shards.
    pub count: u64,
}

impl Shard {
    /// The whole campaign.
    pub const WHOLE: Shard = Shard { index: 1, count: 1 };

    /// Does the shard fly run `i`?
    pub fn contains(self, i: u64) -> bool {
        i % self.count == self.index - 1
    }

    /// The runs of a campaign of `runs` runs that this shard flies, in order.
    pub fn runs(self, runs: u64) -> Vec<u64> {
        (self.index - 1..runs)
            .step_by(self.count as usize)
            .collect()
    }

    /// Parses `K/N` (1 ≤ K ≤ N).
    pub fn parse(s: &str) -> Result<Self, String> {
        let (k, n) = s
            .split_once('/')
            .ok_or_else(|| format!("--shard {s}: expected K/N, e.g. 2/8 (the K-th of N shards)"))?;
        let parse = |t: &str, what: &str| {
            t.trim()
                .parse::<u64>()
                .map_err(|_| format!("--shard {s}: {what} `{t}` is not a whole number"))
        };
        let (index, count) = (parse(k, "K")?, parse(n, "N")?);
        if count == 0 || index == 0 || index > count {
            return Err(format!(
                "--shard {s}: K must be in 1..=N and N at least 1 (e.g. 1/4, 2/4, 3/4, 4/4)"
            ));
        }
        Ok(Self { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// The Slurm array variables `--shard auto` reads.
pub const SLURM_TASK_ID: &str = "SLURM_ARRAY_TASK_ID";
/// Tasks in the array.
pub const SLURM_TASK_COUNT: &str = "SLURM_ARRAY_TASK_COUNT";
/// The array's first task id.
pub const SLURM_TASK_MIN: &str = "SLURM_ARRAY_TASK_MIN";
/// The array's last task id.
pub const SLURM_TASK_MAX: &str = "SLURM_ARRAY_TASK_MAX";
/// The array's step (`--array=0-15:4`); 1 if absent.
pub const SLURM_TASK_STEP: &str = "SLURM_ARRAY_TASK_STEP";
/// A Kubernetes indexed job's 0-based completion index.
pub const K8S_INDEX: &str = "JOB_COMPLETION_INDEX";

/// `--shard`: given, or from the environment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShardSpec {
    /// `K/N`.
    Given(Shard),
    /// `auto` or `auto/N`: from a Slurm job array or a Kubernetes indexed job.
    Auto {
        /// N of `auto/N`.
        count: Option<u64>,
    },
}

impl ShardSpec {
    /// Parses `K/N`, `auto` or `auto/N`.
    pub fn parse(s: &str) -> Result<Self, String> {
        match s.split_once('/') {
            _ if s == "auto" => Ok(Self::Auto { count: None }),
            Some(("auto", n)) => match n.trim().parse::<u64>() {
                Ok(count) if count > 0 => Ok(Self::Auto { count: Some(count) }),
                _ => Err(format!(
                    "--shard {s}: N of auto/N must be a whole number, at least 1"
                )),
            },
            _ => Shard::parse(s).map(Self::Given),
        }
    }

    /// The shard, and where it came from (`None` if given); `var` reads the environment.
    pub fn resolve(
        self,
        var: &dyn Fn(&str) -> Option<String>,
    ) -> Result<(Shard, Option<String>), String> {
        match self {
            Self::Given(shard) => Ok((shard, None)),
            Self::Auto { count } => {
                if var(SLURM_TASK_ID).is_some() {
                    slurm(var, count).map(|(s, from)| (s, Some(from)))
                } else if let Some(index) = var(K8S_INDEX) {
                    kubernetes(&index, count).map(|(s, from)| (s, Some(from)))
                } else {
                    Err(format!(
                        "--shard auto: neither {SLURM_TASK_ID} (a Slurm job array, \
                         `sbatch --array=1-N`) nor {K8S_INDEX} (a Kubernetes indexed job) is \
                         set; outside a batch system give the shard as K/N"
                    ))
                }
            }
        }
    }
}

/// A whole number from the environment variable `name`.
fn number(var: &dyn Fn(&str) -> Option<String>, name: &str) -> Result<u64, String> {
    let text = var(name).ok_or_else(|| {
        format!(
            "--shard auto: {SLURM_TASK_ID} is set but {name} is not (a Slurm job array sets both)"
        )
    })?;
    text.trim()
        .parse()
        .map_err(|_| format!("--shard auto: {name}={text:?} is not a whole number"))
}

/// The shard of a Slurm array task.
fn slurm(
    var: &dyn Fn(&str) -> Option<String>,
    expected: Option<u64>,
) -> Result<(Shard, String), String> {
    let id = number(var, SLURM_TASK_ID)?;
    let count = number(var, SLURM_TASK_COUNT)?;
    let min = number(var, SLURM_TASK_MIN)?;
    let max = number(var, SLURM_TASK_MAX)?;
    let step = match var(SLURM_TASK_STEP) {
        Some(_) => number(var, SLURM_TASK_STEP)?,
        None => 1,
    };
    let array = if step == 1 {
        format!("{min}-{max}")
    } else {
        format!("{min}-{max}:{step}")
    };
    // A range MIN-MAX:STEP has (MAX − MIN)/STEP + 1 tasks; a list (1,3,8) has fewer.
    let is_range = step > 0
        && count > 0
        && max >= min
        && (max - min) % step == 0
        && (max - min) / step + 1 == count;
    if !is_range {
        return Err(format!(
            "--shard auto: the Slurm array's {count} tasks (ids {min} to {max}, step {step}) are \
             not a range MIN-MAX[:STEP], so a task id does not say which shard it is; submit \
             the array as --array=1-{count}"
        ));
    }
    if id < min || id > max || (id - min) % step != 0 {
        return Err(format!(
            "--shard auto: {SLURM_TASK_ID}={id} is not a task of the array {array}"
        ));
    }
    if let Some(n) = expected.filter(|&n| n != count) {
        return Err(format!(
            "--shard auto/{n}: the Slurm array {array} has {count} tasks, not {n}"
        ));
    }
    let shard = Shard {
        index: (id - min) / step + 1,
        count,
    };
    Ok((shard, format!("Slurm array task {id} of {array}")))
}

/// The shard of a Kubernetes indexed job's pod.
fn kubernetes(index: &str, count: Option<u64>) -> Result<(Shard, String), String> {
    let i: u64 = index
        .trim()
        .parse()
        .map_err(|_| format!("--shard auto: {K8S_INDEX}={index:?} is not a whole number"))?;
    let count = count.ok_or_else(|| {
        format!(
            "--shard auto: {K8S_INDEX}={i} is set (a Kubernetes indexed job) but the number of \
             shards is not: give it as --shard auto/N, N the job's completions"
        )
    })?;
    if i >= count {
        return Err(format!(
            "--shard auto/{count}: {K8S_INDEX}={i} is not below {count}"
        ));
    }
    Ok((
        Shard {
            index: i + 1,
            count,
        },
        format!("Kubernetes completion index {i} of 0-{}", count - 1),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env<'a>(pairs: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        move |name| {
            pairs
                .iter()
                .find(|(k, _)| *k == name)
                .map(|(_, v)| v.to_string())
        }
    }

    fn slurm_env(
        id: &str,
        min: &str,
        max: &str,
        count: &str,
        step: &str,
    ) -> Vec<(&'static str, String)> {
        vec![
            (SLURM_TASK_ID, id.to_string()),
            (SLURM_TASK_MIN, min.to_string()),
            (SLURM_TASK_MAX, max.to_string()),
            (SLURM_TASK_COUNT, count.to_string()),
            (SLURM_TASK_STEP, step.to_string()),
        ]
    }

    fn resolve(spec: &str, vars: &[(&str, String)]) -> Result<Shard, String> {
        let pairs: Vec<(&str, &str)> = vars.iter().map(|(k, v)| (*k, v.as_str())).collect();
        let var = env(&pairs);
        let resolved = ShardSpec::parse(spec)?.resolve(&var);
        resolved.map(|(shard, _)| shard)
    }

    #[test]
    fn shards_partition_the_runs() {
        assert_eq!(Shard::parse("2/3").unwrap(), Shard { index: 2, count: 3 });
        for bad in ["0/3", "4/3", "1/0", "x/3", "3", "1/2/3", "-1/3"] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
        let mut all: Vec<u64> = (1..=3)
            .flat_map(|k| Shard { index: k, count: 3 }.runs(10))
            .collect();
        all.sort_unstable();
        assert_eq!(all, (0..10).collect::<Vec<_>>());
        assert_eq!(Shard { index: 2, count: 3 }.runs(10), [1, 4, 7]);
        assert!(Shard { index: 2, count: 3 }.contains(7));
    }

    #[test]
    fn a_slurm_array_task_is_its_shard_whatever_the_first_id() {
        let s = |index, count| Shard { index, count };
        // --array=1-4 and --array=0-3: the same four shards.
        assert_eq!(
            resolve("auto", &slurm_env("1", "1", "4", "4", "1")),
            Ok(s(1, 4))
        );
        assert_eq!(
            resolve("auto", &slurm_env("4", "1", "4", "4", "1")),
            Ok(s(4, 4))
        );
        assert_eq!(
            resolve("auto", &slurm_env("0", "0", "3", "4", "1")),
            Ok(s(1, 4))
        );
        assert_eq!(
            resolve("auto/4", &slurm_env("3", "0", "3", "4", "1")),
            Ok(s(4, 4))
        );
        // --array=10-14 and --array=2-14:4 (tasks 2, 6, 10, 14).
        assert_eq!(
            resolve("auto", &slurm_env("12", "10", "14", "5", "1")),
            Ok(s(3, 5))
        );
        assert_eq!(
            resolve("auto", &slurm_env("10", "2", "14", "4", "4")),
            Ok(s(3, 4))
        );
        // No step variable: step 1.
        let mut no_step = slurm_env("2", "1", "3", "3", "1");
        no_step.pop();
        assert_eq!(resolve("auto", &no_step), Ok(s(2, 3)));
        // Given K/N wins over the environment.
        assert_eq!(
            resolve("2/5", &slurm_env("1", "1", "4", "4", "1")),
            Ok(s(2, 5))
        );
    }

    #[test]
    fn arrays_that_do_not_say_the_shard_are_refused() {
        // A list (--array=1,3,8): three tasks between 1 and 8.
        let e = resolve("auto", &slurm_env("3", "1", "8", "3", "1")).unwrap_err();
        assert!(
            e.contains("not a range") && e.contains("--array=1-3"),
            "{e}"
        );
        // A task id off the step.
        let e = resolve("auto", &slurm_env("3", "2", "14", "4", "4")).unwrap_err();
        assert!(
            e.contains("SLURM_ARRAY_TASK_ID=3 is not a task of the array 2-14:4"),
            "{e}"
        );
        // auto/N that disagrees with the array.
        let e = resolve("auto/3", &slurm_env("1", "1", "4", "4", "1")).unwrap_err();
        assert!(e.contains("has 4 tasks, not 3"), "{e}");
        // A variable missing or not a number.
        let mut partial = slurm_env("1", "1", "4", "4", "1");
        partial.retain(|(k, _)| *k != SLURM_TASK_COUNT);
        let e = resolve("auto", &partial).unwrap_err();
        assert!(e.contains("SLURM_ARRAY_TASK_COUNT is not"), "{e}");
        let e = resolve("auto", &slurm_env("x", "1", "4", "4", "1")).unwrap_err();
        assert!(
            e.contains("SLURM_ARRAY_TASK_ID=\"x\" is not a whole number"),
            "{e}"
        );
    }

    #[test]
    fn a_kubernetes_index_needs_the_count() {
        let k = |i: &str| vec![(K8S_INDEX, i.to_string())];
        assert_eq!(resolve("auto/4", &k("0")), Ok(Shard { index: 1, count: 4 }));
        assert_eq!(resolve("auto/4", &k("3")), Ok(Shard { index: 4, count: 4 }));
        let e = resolve("auto", &k("0")).unwrap_err();
        assert!(e.contains("--shard auto/N"), "{e}");
        let e = resolve("auto/4", &k("4")).unwrap_err();
        assert!(e.contains("is not below 4"), "{e}");
    }

    #[test]
    fn auto_outside_a_batch_system_says_so() {
        let e = resolve("auto", &[]).unwrap_err();
        assert!(
            e.contains("neither SLURM_ARRAY_TASK_ID") && e.contains("JOB_COMPLETION_INDEX"),
            "{e}"
        );
        for bad in ["auto/0", "auto/x", "autox", "auto/"] {
            assert!(ShardSpec::parse(bad).is_err(), "{bad}");
        }
    }
}
