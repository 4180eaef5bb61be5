//! `gi-studio farm`: the scripts that run a render as shards on a cluster
//! and merge them once every shard is done. SLURM: an array job of K tasks
//! (each reading `SLURM_ARRAY_TASK_ID`) and a merge job that waits for it
//! (`--dependency=afterok`). Kubernetes: an Indexed Job of K completions
//! (each reading `JOB_COMPLETION_INDEX`) on a shared volume, and a merge
//! Job applied once it completes. The scene is copied beside the scripts,
//! so editing it later changes nothing of a render under way.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand};

use super::outputs::Outputs;
use super::RenderFlags;
use crate::fileio::{self, SIGNATURE};
use crate::limits;
use crate::scene::load_scene;

#[derive(Debug, Args)]
pub struct FarmArgs {
    #[command(subcommand)]
    pub target: FarmTarget,
}

#[derive(Debug, Subcommand)]
pub enum FarmTarget {
    /// An sbatch array job and a merge job after it, and submit.sh.
    Slurm(FarmJob),
    /// A Kubernetes Indexed Job and a merge Job, and run.sh.
    K8s(KubernetesJob),
}

#[derive(Debug, Args)]
pub struct FarmJob {
    /// Scene file (RON).
    pub scene: PathBuf,
    /// Shards to split the render into.
    #[arg(long, value_parser = |s: &str| limits::SHARDS.parse(s))]
    pub shards: u32,
    /// Folder for the scripts, the scene's copy, the parts and the image.
    #[arg(long)]
    pub out: PathBuf,
    /// The merged image's file name in that folder.
    #[arg(long, default_value = "merged.exr")]
    pub image: String,
    /// Cores each shard asks for.
    #[arg(long, default_value_t = 2, value_parser = |s: &str| limits::THREADS.parse(s))]
    pub cpus: usize,
    /// Replace scripts GI Studio did not write.
    #[arg(long)]
    pub force: bool,
    /// `render`'s flags, after `--` (--spp is needed: the passes to share).
    #[arg(last = true)]
    pub render: Vec<String>,
}

#[derive(Debug, Args)]
pub struct KubernetesJob {
    #[command(flatten)]
    pub job: FarmJob,
    /// The container image holding gi-studio on its PATH.
    #[arg(long, default_value = "gi-studio:latest")]
    pub container: String,
    /// The persistent volume claim mounted at /farm in every pod.
    #[arg(long, default_value = "gi-studio-farm")]
    pub claim: String,
}

/// `render`'s flags alone, to check them before writing anything.
#[derive(Debug, Parser)]
struct RenderFlagsOnly {
    #[command(flatten)]
    flags: RenderFlags,
}

/// A word for a POSIX shell, single-quoted.
fn quoted(word: &str) -> String {
    format!("'{}'", word.replace('\'', "'\\''"))
}

/// The farm's folder prepared: the render flags checked against the scene
/// (a mistake fails here, not on the cluster), the scene copied in.
struct Prepared {
    dir: PathBuf,
    flags: String,
}

fn prepare(job: &FarmJob, files: &[&str]) -> Result<Prepared> {
    let parsed = RenderFlagsOnly::try_parse_from(std::iter::once("render".to_string()).chain(job.render.clone()))
        .map_err(|e| anyhow::anyhow!("the render flags after --: {}", e.to_string().trim()))?;
    if parsed.flags.spp.is_none() || parsed.flags.time.is_some() {
        bail!("give the render's --spp after --: the shards share its passes (a --time budget cannot be shared)");
    }
    let scene = load_scene(&job.scene)?;
    let settings = parsed.flags.settings(&scene)?;
    let total = settings.samples_per_pixel.unwrap_or(0);
    if job.shards > total {
        bail!("{} shards of {total} passes: some would have none", job.shards);
    }
    if job.render.iter().any(|f| f == "--shard" || f.starts_with("--shard=") || f == "-o" || f == "--output") {
        bail!("the render flags after -- must not name a shard or an output: the farm gives each shard its own");
    }
    std::fs::create_dir_all(job.out.join("parts")).with_context(|| job.out.display().to_string())?;
    std::fs::create_dir_all(job.out.join("logs")).with_context(|| job.out.display().to_string())?;
    let dir = std::fs::canonicalize(&job.out).with_context(|| job.out.display().to_string())?;
    let mut outputs = Outputs::new(job.force);
    outputs.input(&job.scene);
    for name in std::iter::once("scene.ron").chain(files.iter().copied()) {
        outputs.claim(&dir.join(name), &[SIGNATURE.as_bytes()])?;
    }
    // The scene as it is now, marked as ours so a second farm run may replace it
    let text = fileio::read_text(&job.scene, limits::TEXT_FILE_BYTES)?;
    fileio::write_bytes(&dir.join("scene.ron"), format!("// {SIGNATURE}: the scene of this farm\n{text}").as_bytes())?;
    let flags = job.render.iter().map(|f| quoted(f)).collect::<Vec<_>>().join(" ");
    Ok(Prepared { dir, flags })
}

/// The binary the cluster runs: this one, by its full path.
fn binary() -> Result<String> {
    let exe = std::env::current_exe().context("where this program is")?;
    Ok(quoted(&exe.display().to_string()))
}

fn write_script(path: &Path, text: &str) -> Result<()> {
    fileio::write_bytes(path, text.as_bytes())?;
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).with_context(|| path.display().to_string())
}

pub fn run(args: &FarmArgs) -> Result<()> {
    match &args.target {
        FarmTarget::Slurm(job) => slurm(job),
        FarmTarget::K8s(k8s) => kubernetes(k8s),
    }
}

fn slurm(job: &FarmJob) -> Result<()> {
    let p = prepare(job, &["render.sbatch", "merge.sbatch", "submit.sh"])?;
    let (dir, bin, k) = (&p.dir, binary()?, job.shards);
    let d = quoted(&dir.display().to_string());
    let render = format!(
        "#!/bin/bash\n# {SIGNATURE}: shard $SLURM_ARRAY_TASK_ID of {k}\n#SBATCH --job-name=gi-studio-render\n\
         #SBATCH --array=0-{last}\n#SBATCH --cpus-per-task={cpus}\n#SBATCH --output={dir}/logs/shard-%a.log\n\
         set -euo pipefail\n\
         {bin} render {d}/scene.ron {flags} --threads {cpus} --shard \"$SLURM_ARRAY_TASK_ID/{k}\" \\\n    \
         -o {d}/parts/part-\"$SLURM_ARRAY_TASK_ID\".exr --force\n",
        last = k - 1,
        cpus = job.cpus,
        dir = dir.display(),
        flags = p.flags,
    );
    let image = quoted(&job.image);
    let merge = format!(
        "#!/bin/bash\n# {SIGNATURE}: the merge, once every shard is done\n#SBATCH --job-name=gi-studio-merge\n\
         #SBATCH --output={dir}/logs/merge.log\nset -euo pipefail\n\
         {bin} merge {d}/parts/part-*.exr -o {d}/{image} --force\n",
        dir = dir.display(),
    );
    let submit = format!(
        "#!/bin/bash\n# {SIGNATURE}: submit the shards, then the merge after them\nset -euo pipefail\n\
         cd {d}\narray=$(sbatch --parsable render.sbatch)\n\
         merge=$(sbatch --parsable --dependency=afterok:\"${{array%%;*}}\" merge.sbatch)\n\
         echo \"shards: job $array; merge: job $merge → {dir}/{img}\"\n",
        dir = dir.display(),
        img = job.image,
    );
    write_script(&dir.join("render.sbatch"), &render)?;
    write_script(&dir.join("merge.sbatch"), &merge)?;
    write_script(&dir.join("submit.sh"), &submit)?;
    println!(
        "wrote {0}/render.sbatch ({k} shards), {0}/merge.sbatch and {0}/submit.sh; run {0}/submit.sh",
        dir.display()
    );
    Ok(())
}

fn kubernetes(k8s: &KubernetesJob) -> Result<()> {
    let job = &k8s.job;
    let p = prepare(job, &["render-job.yaml", "merge-job.yaml", "run.sh"])?;
    let k = job.shards;
    let image = quoted(&job.image);
    // The pods see the farm's folder at /farm, through the claim
    let render_command =
        format!("gi-studio render /farm/scene.ron {} --threads {} --shard \"$JOB_COMPLETION_INDEX/{k}\" -o /farm/parts/part-\"$JOB_COMPLETION_INDEX\".exr --force", p.flags, job.cpus);
    let merge_command = format!("gi-studio merge /farm/parts/part-*.exr -o /farm/{image} --force");
    let yaml = |name: &str, indexed: bool, command: &str| {
        let indexed = if indexed {
            format!("  completions: {k}\n  parallelism: {k}\n  completionMode: Indexed\n")
        } else {
            String::new()
        };
        format!(
            "# {SIGNATURE}: {name}\napiVersion: batch/v1\nkind: Job\nmetadata:\n  name: gi-studio-{name}\nspec:\n{indexed}  backoffLimit: 2\n  template:\n    spec:\n      restartPolicy: Never\n      containers:\n        - name: {name}\n          image: {container}\n          resources:\n            requests:\n              cpu: \"{cpus}\"\n          command: [\"/bin/sh\", \"-c\"]\n          args:\n            - {command}\n          volumeMounts:\n            - name: farm\n              mountPath: /farm\n      volumes:\n        - name: farm\n          persistentVolumeClaim:\n            claimName: {claim}\n",
            container = k8s.container,
            cpus = job.cpus,
            command = serde_quoted(command),
            claim = k8s.claim,
        )
    };
    let run = format!(
        "#!/bin/bash\n# {SIGNATURE}: the shards, then the merge once they complete\n\
         # (the claim {claim} must hold this folder's scene.ron and a parts/ folder at /farm)\nset -euo pipefail\n\
         cd {d}\nkubectl apply -f render-job.yaml\n\
         kubectl wait --for=condition=complete --timeout=24h job/gi-studio-render\n\
         kubectl apply -f merge-job.yaml\n",
        claim = k8s.claim,
        d = quoted(&p.dir.display().to_string()),
    );
    fileio::write_bytes(&p.dir.join("render-job.yaml"), yaml("render", true, &render_command).as_bytes())?;
    fileio::write_bytes(&p.dir.join("merge-job.yaml"), yaml("merge", false, &merge_command).as_bytes())?;
    write_script(&p.dir.join("run.sh"), &run)?;
    println!("wrote {0}/render-job.yaml (an Indexed Job of {k}), {0}/merge-job.yaml and {0}/run.sh", p.dir.display());
    Ok(())
}

/// A YAML double-quoted string.
fn serde_quoted(text: &str) -> String {
    format!("\"{}\"", text.replace('\\', "\\\\").replace('"', "\\\""))
}
