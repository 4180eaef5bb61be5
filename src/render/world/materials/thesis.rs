//! How Whitted's ray tracer sees a material, with the thesis' models: its
//! local model toward a light, its share of the ambient light, and how the
//! light its reflected and refracted rays bring back joins them. Each
//! material writes its view beside its `Scatter`, in its own file.

use glam::Vec3;

use super::{At, Bsdf};
use crate::scene::Rgb;

/// The rays a hit spawns, as shares of the light they bring back: the
/// reflected ray's (0 where none is traced) and the refracted ray with its
/// share (None where there is none).
#[derive(Clone, Copy, Debug)]
pub struct Shares {
    pub reflected: f32,
    pub refracted: Option<(Vec3, f32)>,
}

impl Shares {
    pub const NONE: Shares = Shares { reflected: 0.0, refracted: None };
}

/// The light the reflected and refracted rays brought back, where they were
/// traced.
#[derive(Clone, Copy, Debug)]
pub struct Brought {
    pub reflected: Option<Rgb>,
    pub refracted: Option<Rgb>,
}

/// A material as the thesis models it.
pub trait Thesis {
    /// Lights shade it: a light sample per light.
    const LIT: bool;

    /// The local model toward a light in direction `wi` at cosine `cos`,
    /// before the light's colour: `kd·cos + ks·(r·v)^α` (Blinn–Phong's
    /// `(n·h)^α`); zero where lights do not shade it.
    fn local(&self, _at: &At<f32>, _wi: Vec3, _cos: f32) -> Rgb {
        Rgb::ZERO
    }

    /// The shares of the rays it spawns.
    fn shares(&self, at: &At<f32>) -> Shares;

    /// The light leaving toward `wo`: from the ambient light on it
    /// (`ambient`, the scene's times the material's ambient colour), its
    /// local model over every light (`local`), and what its rays `brought`.
    fn combine(&self, ambient: Rgb, local: Rgb, brought: Brought, at: &At<f32>) -> Rgb;
}

impl Bsdf {
    /// `Thesis::LIT` (emitters are not lit).
    pub fn thesis_lit(&self) -> bool {
        each_material!(self, m => lit(m), black => false)
    }

    /// `Thesis::local`.
    pub fn thesis_local(&self, at: &At<f32>, wi: Vec3, cos: f32) -> Rgb {
        each_material!(self, m => m.local(at, wi, cos), black => Rgb::ZERO)
    }

    /// `Thesis::shares` (an emitter spawns nothing).
    pub fn thesis_shares(&self, at: &At<f32>) -> Shares {
        each_material!(self, m => m.shares(at), black => Shares::NONE)
    }

    /// `Thesis::combine`; None for an emitter, whose light is its emission.
    pub fn thesis_combine(&self, ambient: Rgb, local: Rgb, brought: Brought, at: &At<f32>) -> Option<Rgb> {
        each_material!(self, m => Some(m.combine(ambient, local, brought, at)), black => None)
    }
}

fn lit<M: Thesis>(_: &M) -> bool {
    M::LIT
}
