//! The materials at eight hits: every shape's material in columns
//! (`MaterialTable`, a column a field, indexed by shape), and
//! `LaneSurfaces`, which runs each material present among eight lanes on
//! the lanes that hold it, through the same `Scatter` functions `Bsdf`
//! calls, each lane drawing from its own stream the numbers the scalar
//! code draws.

use glam::Vec3;

use super::microfacet::Ggx;
use super::{
    At, BlinnPhong, Bsdf, Draws, Glass, Lambert, Mirror, Phong, RoughConductor, Sampled, Scatter, SmoothConductor,
    Transport,
};
use crate::render::world::lanes::{Column, Column3, Index8, Rng8, F8, M8, V8};
use crate::scene::{MaterialModel, Rgb};

/// Each `Bsdf` variant, as a float the lanes compare eight at a time.
const LAMBERT: f32 = 0.0;
const MIRROR: f32 = 1.0;
const GLASS: f32 = 2.0;
const EMITTER: f32 = 3.0;
const PHONG: f32 = 4.0;
const BLINN_PHONG: f32 = 5.0;
const ROUGH_CONDUCTOR: f32 = 6.0;
const SMOOTH_CONDUCTOR: f32 = 7.0;

impl Draws<F8> for Rng8 {
    #[inline(always)]
    fn next_1d(&mut self, lanes: M8) -> F8 {
        self.next_f32(lanes)
    }

    #[inline(always)]
    fn next_2d(&mut self, lanes: M8) -> (F8, F8) {
        Rng8::next_2d(self, lanes)
    }
}

/// One shape's material, as the lanes read it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Record {
    /// The object the shape belongs to.
    pub(crate) object: u32,
    /// `LAMBERT`, `MIRROR`, …: which `Bsdf` variant.
    kind: f32,
    /// Albedo, tint, an emitter's radiance or a glossy surface's diffuse part.
    pub(crate) color: Rgb,
    ior: f32,
    /// A glossy surface's lobe: its colour, exponent, the chance of
    /// sampling the diffuse part and Blinn–Phong's normalisation.
    specular: Rgb,
    exponent: f32,
    diffuse_probability: f32,
    normalisation: f32,
    /// A metal's complex index and its roughness along the frame's axes.
    eta: Rgb,
    k: Rgb,
    alpha_x: f32,
    alpha_y: f32,
}

impl Record {
    fn new(object: u32, material: &MaterialModel) -> Self {
        let plain = |kind, color: Vec3| Record {
            object,
            kind,
            color,
            ior: 1.0,
            specular: Rgb::ZERO,
            exponent: 0.0,
            diffuse_probability: 1.0,
            normalisation: 0.0,
            eta: Rgb::ONE,
            k: Rgb::ZERO,
            alpha_x: 1.0,
            alpha_y: 1.0,
        };
        match Bsdf::new(material) {
            Bsdf::Lambert(m) => plain(LAMBERT, m.albedo.into()),
            Bsdf::Mirror(m) => plain(MIRROR, m.tint.into()),
            Bsdf::Glass(m) => Record { ior: m.ior, ..plain(GLASS, m.tint.into()) },
            Bsdf::Phong(m) => Record {
                specular: m.ks.into(),
                exponent: m.exponent,
                diffuse_probability: m.diffuse_probability,
                ..plain(PHONG, m.kd.into())
            },
            Bsdf::BlinnPhong(m) => Record {
                specular: m.ks.into(),
                exponent: m.exponent,
                diffuse_probability: m.diffuse_probability,
                normalisation: m.normalisation,
                ..plain(BLINN_PHONG, m.kd.into())
            },
            Bsdf::RoughConductor(m) => Record {
                eta: m.eta.into(),
                k: m.k.into(),
                alpha_x: m.ggx.alpha_x,
                alpha_y: m.ggx.alpha_y,
                ..plain(ROUGH_CONDUCTOR, Rgb::ZERO)
            },
            Bsdf::SmoothConductor(m) => {
                Record { eta: m.eta.into(), k: m.k.into(), ..plain(SMOOTH_CONDUCTOR, Rgb::ZERO) }
            }
            Bsdf::Black => match *material {
                MaterialModel::Emissive { radiance } => plain(EMITTER, radiance),
                // Reflects nothing, emits nothing: an emitter gone dark
                _ => plain(EMITTER, Rgb::ZERO),
            },
        }
    }
}

/// Every shape's material: the records, and a column per field for the
/// lanes to read eight at a time.
#[derive(Clone, Debug)]
pub(crate) struct MaterialTable {
    pub(crate) records: Vec<Record>,
    kind: Column,
    color: Column3,
    ior: Column,
    specular: Column3,
    exponent: Column,
    diffuse_probability: Column,
    normalisation: Column,
    eta: Column3,
    k: Column3,
    alpha_x: Column,
    alpha_y: Column,
}

impl MaterialTable {
    /// For shapes of the objects `objects`, `material` giving each object's.
    pub(crate) fn new<'m>(objects: impl Iterator<Item = u32>, material: impl Fn(u32) -> &'m MaterialModel) -> Self {
        let records: Vec<Record> = objects.map(|object| Record::new(object, material(object))).collect();
        let column = |field: fn(&Record) -> f32| Column::new(records.iter().map(field));
        let column3 = |field: fn(&Record) -> Vec3| Column3::new(records.iter().map(field));
        MaterialTable {
            kind: column(|r| r.kind),
            color: column3(|r| r.color),
            ior: column(|r| r.ior),
            specular: column3(|r| r.specular),
            exponent: column(|r| r.exponent),
            diffuse_probability: column(|r| r.diffuse_probability),
            normalisation: column(|r| r.normalisation),
            eta: column3(|r| r.eta),
            k: column3(|r| r.k),
            alpha_x: column(|r| r.alpha_x),
            alpha_y: column(|r| r.alpha_y),
            records,
        }
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.records.is_empty()
    }
}

/// Directions drawn at eight hits (`Bsdf::sample`).
pub(crate) struct Scattered {
    /// The lanes that scattered (the others' paths end).
    pub(crate) go: M8,
    /// Lanes whose draws are deltas (on mirrors and glass).
    pub(crate) delta: M8,
    pub(crate) wi: V8,
    /// f · cos / pdf.
    pub(crate) weight: V8,
    pub(crate) pdf: F8,
}

impl Scattered {
    /// `sampled`'s draws in the lanes of `lanes`.
    #[inline(always)]
    fn take(&mut self, lanes: M8, sampled: Sampled<F8>) {
        self.go = self.go.or(sampled.go.and(lanes));
        self.wi = lanes.select_v(sampled.wi, self.wi);
        self.weight = lanes.select_v(sampled.weight, self.weight);
        self.pdf = lanes.select(sampled.pdf, self.pdf);
    }
}

/// The materials of the lanes of `alive`: each variant's lanes, and its
/// parameters gathered where some lane holds it.
pub(crate) struct LaneSurfaces<'a> {
    table: &'a MaterialTable,
    /// Each lane's shape.
    index: Index8,
    lambert: M8,
    phong: M8,
    blinn_phong: M8,
    mirror: M8,
    glass: M8,
    rough_conductor: M8,
    smooth_conductor: M8,
    /// Emitters, and surfaces that neither reflect nor emit.
    pub(crate) emissive: M8,
    /// Albedo, tint, radiance or a glossy surface's diffuse part.
    pub(crate) color: V8,
    /// The glossy lanes' lobes (zeros where no lane is glossy).
    phong_lobe: Phong<F8>,
    blinn_phong_lobe: BlinnPhong<F8>,
}

impl<'a> LaneSurfaces<'a> {
    /// `index` names each lane's shape in `table` (lanes outside `alive`
    /// read any).
    #[inline(always)]
    pub(crate) fn new(table: &'a MaterialTable, index: Index8, alive: M8) -> Self {
        let code = table.kind.get(index);
        let kind = |k: f32| code.eq(F8::splat(k)).and(alive);
        let color = table.color.get(index);
        let (phong, blinn_phong) = (kind(PHONG), kind(BLINN_PHONG));
        // The lobes' parameters gathered only where a lane is glossy: a
        // scene without a glossy surface would gather them at every bounce
        // for nothing
        let (ks, exponent, diffuse_probability, normalisation) = match phong.or(blinn_phong).any() {
            true => (
                table.specular.get(index),
                table.exponent.get(index),
                table.diffuse_probability.get(index),
                table.normalisation.get(index),
            ),
            false => (V8::splat(Vec3::ZERO), F8::splat(0.0), F8::splat(0.0), F8::splat(0.0)),
        };

        LaneSurfaces {
            lambert: kind(LAMBERT),
            phong,
            blinn_phong,
            mirror: kind(MIRROR),
            glass: kind(GLASS),
            rough_conductor: kind(ROUGH_CONDUCTOR),
            smooth_conductor: kind(SMOOTH_CONDUCTOR),
            emissive: kind(EMITTER),
            color,
            phong_lobe: Phong { kd: color, ks, exponent, diffuse_probability },
            blinn_phong_lobe: BlinnPhong { kd: color, ks, exponent, diffuse_probability, normalisation },
            table,
            index,
        }
    }

    /// Only the lanes of `lanes` left (the others' surfaces scatter nothing).
    #[inline(always)]
    pub(crate) fn keep(&mut self, lanes: M8) {
        self.lambert = self.lambert.and(lanes);
        self.phong = self.phong.and(lanes);
        self.blinn_phong = self.blinn_phong.and(lanes);
        self.mirror = self.mirror.and(lanes);
        self.glass = self.glass.and(lanes);
        self.rough_conductor = self.rough_conductor.and(lanes);
        self.smooth_conductor = self.smooth_conductor.and(lanes);
        self.emissive = self.emissive.and(lanes);
    }

    /// The rough metals' lobes, gathered when some lane holds one.
    #[inline(always)]
    fn rough_conductor(&self) -> RoughConductor<F8> {
        let (table, index) = (self.table, self.index);
        let ggx = Ggx { alpha_x: table.alpha_x.get(index), alpha_y: table.alpha_y.get(index) };
        RoughConductor { eta: table.eta.get(index), k: table.k.get(index), ggx }
    }

    /// `Bsdf::is_specular`: mirrors, glass, polished metals, and what
    /// reflects nothing.
    #[inline(always)]
    pub(crate) fn specular(&self) -> M8 {
        self.mirror.or(self.glass).or(self.smooth_conductor).or(self.emissive)
    }

    /// The lanes whose surface is not specular: where lights are sampled.
    #[inline(always)]
    pub(crate) fn shaded(&self) -> M8 {
        self.lambert.or(self.phong).or(self.blinn_phong).or(self.rough_conductor)
    }

    /// `Bsdf::eval_pdf` for `wo` and `wi` above the surface of normal `n`,
    /// in the lanes of `wanted` that are `shaded`.
    #[inline(always)]
    pub(crate) fn eval_pdf(&self, wanted: M8, wo: V8, wi: V8, n: V8) -> (V8, F8) {
        // Lambert's costs less than asking which lanes hold it
        let (mut f, mut pdf) = Lambert { albedo: self.color }.eval_pdf(wo, wi, n);
        let phong = self.phong.and(wanted);
        if phong.any() {
            let (phong_f, phong_pdf) = self.phong_lobe.eval_pdf(wo, wi, n);
            (f, pdf) = (phong.select_v(phong_f, f), phong.select(phong_pdf, pdf));
        }
        let blinn_phong = self.blinn_phong.and(wanted);
        if blinn_phong.any() {
            let (blinn_f, blinn_pdf) = self.blinn_phong_lobe.eval_pdf(wo, wi, n);
            (f, pdf) = (blinn_phong.select_v(blinn_f, f), blinn_phong.select(blinn_pdf, pdf));
        }
        let rough_conductor = self.rough_conductor.and(wanted);
        if rough_conductor.any() {
            let (metal_f, metal_pdf) = self.rough_conductor().eval_pdf(wo, wi, n);
            (f, pdf) = (rough_conductor.select_v(metal_f, f), rough_conductor.select(metal_pdf, pdf));
        }
        (f, pdf)
    }

    /// `Bsdf::sample` at each lane's surface, from the direction `wo`
    /// toward where the path came from, the geometric `normal` and it
    /// turned to `wo`'s side (`facing`).
    #[inline(always)]
    pub(crate) fn scatter(&self, rng: &mut Rng8, wo: V8, normal: V8, facing: V8, transport: Transport) -> Scattered {
        let at = At { wo, normal, facing };
        let zero = V8::splat(Vec3::ZERO);
        let mut out = Scattered { go: M8::NONE, delta: self.specular(), wi: zero, weight: zero, pdf: F8::splat(0.0) };
        if self.lambert.any() {
            let lambert = Lambert { albedo: self.color };
            out.take(self.lambert, lambert.sample(self.lambert, &at, rng, transport));
        }
        if self.phong.any() {
            out.take(self.phong, self.phong_lobe.sample(self.phong, &at, rng, transport));
        }
        if self.blinn_phong.any() {
            let sampled = self.blinn_phong_lobe.sample(self.blinn_phong, &at, rng, transport);
            out.take(self.blinn_phong, sampled);
        }
        if self.mirror.any() {
            let mirror = Mirror { tint: self.color };
            out.take(self.mirror, mirror.sample(self.mirror, &at, rng, transport));
        }
        if self.glass.any() {
            let glass = Glass { ior: self.table.ior.get(self.index), tint: self.color };
            out.take(self.glass, glass.sample(self.glass, &at, rng, transport));
        }
        if self.rough_conductor.any() {
            let sampled = self.rough_conductor().sample(self.rough_conductor, &at, rng, transport);
            out.take(self.rough_conductor, sampled);
        }
        if self.smooth_conductor.any() {
            let metal = SmoothConductor { eta: self.table.eta.get(self.index), k: self.table.k.get(self.index) };
            out.take(self.smooth_conductor, metal.sample(self.smooth_conductor, &at, rng, transport));
        }
        out
    }
}
