//! `gi-studio photons`: trace a scene's photon maps once and save them.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Result;
use clap::Args;
use indicatif::ProgressBar;

use super::outputs::Outputs;
use super::render::map_line;
use super::RenderFlags;
use crate::render::integrators::photon_map::file::{save_photon_maps, settings_key, MAGIC};
use crate::render::integrators::photon_map::PhotonMaps;
use crate::render::world::camera::CameraModel;
use crate::render::world::World;
use crate::render::{Algorithm, Method};
use crate::scene::load_scene;

#[derive(Debug, Args)]
pub struct PhotonsArgs {
    /// Scene file (RON).
    pub scene: PathBuf,
    /// Where to write the maps (e.g. caustics.pmap).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub flags: RenderFlags,
}

pub fn run(args: &PhotonsArgs) -> Result<()> {
    let scene = load_scene(&args.scene)?;
    let mut outputs = Outputs::new(args.flags.force);
    outputs.input(&args.scene);
    outputs.claim(&args.output, &[MAGIC])?;
    // The maps are photon mapping's, whatever --algo says
    let settings = args.flags.settings_as(&scene, Algorithm::Photon)?;
    let Method::Photon(photon) = &settings.method else {
        unreachable!("settings_as(Photon) gives photon mapping");
    };
    let bar = ProgressBar::new_spinner().with_message("tracing photons");
    bar.enable_steady_tick(Duration::from_millis(120));
    let camera = CameraModel::new(&scene.camera, settings.width, settings.height);
    let (world, _) = World::for_view(&scene, &camera, settings.width, settings.height);
    let maps = (args.flags.workers()?).run(|| PhotonMaps::build(&world, photon, settings.seed, settings.max_depth));
    bar.finish_and_clear();
    let key = settings_key(photon, settings.seed, settings.max_depth);
    save_photon_maps(&maps, scene.content_key(), key, &args.output)?;
    println!("{}", map_line("global", &maps.stats.global));
    println!("{}", map_line("caustic", &maps.stats.caustic));
    println!("→ {}", args.output.display());
    Ok(())
}
