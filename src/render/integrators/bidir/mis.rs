//! Multiple importance sampling for every strategy that joins a light
//! subpath to a camera subpath, by running partial sums (Georgiev et al.,
//! "Light Transport Simulation with Vertex Connection and Merging", 2012,
//! and its technical report "Implementing Vertex Connection and Merging"):
//! each subpath vertex carries three quantities (`Partials`) from which the
//! weight of a connection or a merge at it follows in constant time, not a
//! loop over the whole path. The functions here are pure arithmetic on
//! densities, so a test can drive them along any path and check that the
//! weights of all strategies that make it sum to one.
//!
//! Densities are per solid angle (W) or per area (A); each includes the
//! Russian roulette continuation probability of the vertex it leaves.
//! `mis(x)` is x for the balance heuristic, x² for the power heuristic. The
//! sums are kept in f64: squared, a grazing hit on a floor a thousand units
//! off overflows f32 (seen on `lights.ron`: an infinite sum, then a NaN).

use crate::render::settings::MisHeuristic;

/// Which strategies a pass uses, and the constants that weigh them.
#[derive(Clone, Copy, Debug)]
pub struct Strategies {
    pub heuristic: MisHeuristic,
    /// Vertex connection: next-event estimation, light subpath to camera
    /// (t = 1) and every connection of two subpath vertices.
    pub connect: bool,
    /// Vertex merging: camera vertices gather the light vertices within
    /// the merge radius.
    pub merge: bool,
    /// Merges only where light came to the vertex through a mirror or
    /// glass (a caustic path), which no connection can make; every other
    /// path is left to the connections, which make it without the merge's
    /// blur, and most light vertices stay out of the grid. (Lightweight
    /// photon mapping, Grittmann et al. 2018, likewise keeps photon
    /// mapping to the paths a path tracer samples badly.) Whether a merge
    /// at a vertex is a strategy depends on the path alone, so the weights
    /// still sum to one.
    pub caustic_merges: bool,
    /// Light subpaths per pass (one a pixel).
    pub light_paths: f32,
    /// mis(η) where merging is on, η = π r² · light paths: how a merge
    /// weighs against a connection (0 without merging).
    pub vm_weight: f64,
    /// mis(1/η) where connecting is on (0 without).
    pub vc_weight: f64,
    /// 1/(π r² · light paths): a merge's density estimate.
    pub vm_normalization: f32,
}

impl Strategies {
    /// For a pass of `light_paths` subpaths merging within `radius`.
    pub fn new(heuristic: MisHeuristic, connect: bool, merge: bool, light_paths: f32, radius: f32) -> Self {
        Self::with_merges(heuristic, connect, merge, false, light_paths, radius)
    }

    /// As `new`, merging only on caustic paths if `caustic_merges` (and
    /// merging at all).
    pub fn with_merges(
        heuristic: MisHeuristic,
        connect: bool,
        merge: bool,
        caustic_merges: bool,
        light_paths: f32,
        radius: f32,
    ) -> Self {
        let mis = |x: f64| heuristic.apply(x);
        let eta = std::f64::consts::PI * (radius as f64).powi(2) * light_paths as f64;
        Strategies {
            heuristic,
            connect,
            merge,
            caustic_merges: merge && caustic_merges,
            light_paths,
            vm_weight: if merge { mis(eta) } else { 0.0 },
            vc_weight: if connect { mis(1.0 / eta) } else { 0.0 },
            vm_normalization: (1.0 / eta) as f32,
        }
    }

    /// Whether a merge at a non-specular vertex is a strategy, light
    /// having come to it through a specular vertex if `after_specular`.
    #[inline]
    pub fn merges_at(&self, after_specular: bool) -> bool {
        self.merge && (after_specular || !self.caustic_merges)
    }

    /// A merge's weight against a connection at such a vertex, 0 where it
    /// is not a strategy.
    #[inline]
    fn vm_weight_at(&self, after_specular: bool) -> f64 {
        if self.merges_at(after_specular) {
            self.vm_weight
        } else {
            0.0
        }
    }

    #[inline]
    pub fn mis(&self, x: f32) -> f64 {
        self.heuristic.apply(x as f64)
    }

    #[inline]
    fn mis64(&self, x: f64) -> f64 {
        self.heuristic.apply(x)
    }
}

impl MisHeuristic {
    #[inline]
    pub fn apply(self, x: f64) -> f64 {
        match self {
            MisHeuristic::Power => x * x,
            MisHeuristic::Balance => x,
        }
    }
}

/// 1/(1 + the other strategies' sums), 0 where a sum overflowed.
#[inline]
fn weight(others: f64) -> f32 {
    let w = 1.0 / (1.0 + others);
    if w.is_finite() {
        w as f32
    } else {
        0.0
    }
}

/// The running quantities of one subpath (the report's dVCM, dVC, dVM).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Partials {
    pub vcm: f64,
    pub vc: f64,
    pub vm: f64,
}

impl Partials {
    /// A camera subpath whose first ray had density `ray_pdf`
    /// (`CameraModel::ray_pdf`) [report (31)–(33)].
    pub fn camera(s: &Strategies, ray_pdf: f32) -> Self {
        Partials { vcm: s.mis64(s.light_paths as f64 / ray_pdf as f64), vc: 0.0, vm: 0.0 }
    }

    /// A light subpath leaving a light with density `emission_pdf`
    /// (`Emission::pdf` times the light's pick probability) at cosine
    /// `cos` [report (31)–(33), (48)–(50)]. Its `vcm` is finished at the
    /// first hit (`first_hit`), where the density next-event estimation
    /// would have had of the light's point is known.
    pub fn light(s: &Strategies, emission_pdf: f32, cos: f32, delta: bool) -> Self {
        let vc = if delta { 0.0 } else { s.mis64(cos as f64 / emission_pdf as f64) };
        Partials { vcm: s.mis64(1.0 / emission_pdf as f64), vc, vm: vc * s.vc_weight }
    }

    /// At a light subpath's first hit: `direct_pdf` is the density with which
    /// next-event estimation from the hit would choose the light's point
    /// (per area, or per solid angle for an infinite light; times the pick
    /// probability).
    pub fn first_hit(&mut self, s: &Strategies, direct_pdf: f32) {
        self.vcm *= s.mis(direct_pdf);
    }

    /// Arriving at a vertex after a segment of squared length `distance2`
    /// (None for the first from an infinite light, measured per solid angle)
    /// at cosine `cos` with the surface there.
    #[inline]
    pub fn arrive(&mut self, s: &Strategies, distance2: Option<f32>, cos: f32) {
        if let Some(d2) = distance2 {
            self.vcm *= s.mis(d2);
        }
        let inverse = 1.0 / s.mis(cos.abs());
        self.vcm *= inverse;
        self.vc *= inverse;
        self.vm *= inverse;
    }

    /// Leaving a vertex along a direction sampled with density `pdf`, whose
    /// reverse density (sampling the way back) is `reverse_pdf`, at cosine
    /// `cos_out`; `specular` for a delta lobe [report (34)–(36), (53)–(55)].
    /// A merge at the vertex is counted if `merges_here`; if not, and merges
    /// are caustic only, what it would have added is returned, for a camera
    /// subpath that learns only at its next vertex whether the merge is a
    /// strategy (`merge_behind`).
    #[inline]
    pub fn scatter(
        &mut self,
        s: &Strategies,
        pdf: f32,
        reverse_pdf: f32,
        cos_out: f32,
        specular: bool,
        merges_here: bool,
    ) -> MergeBehind {
        let g = s.mis64(cos_out.abs() as f64 / pdf as f64);
        if specular {
            self.vcm = 0.0;
            self.vc *= g * s.mis(reverse_pdf);
            self.vm *= g * s.mis(reverse_pdf);
            MergeBehind(0.0)
        } else {
            let (vm_weight, one) = if merges_here { (s.vm_weight, 1.0) } else { (0.0, 0.0) };
            self.vc = g * (self.vc * s.mis(reverse_pdf) + self.vcm + vm_weight);
            self.vm = g * (self.vm * s.mis(reverse_pdf) + self.vcm * s.vc_weight + one);
            self.vcm = s.mis64(1.0 / pdf as f64);
            // Only caustic merges are ever counted later
            MergeBehind(if merges_here || !s.caustic_merges { 0.0 } else { g })
        }
    }

    /// Counts the merge at the vertex before, which `scatter` left out:
    /// light reached this vertex's way through a specular one.
    #[inline]
    pub fn merge_behind(&mut self, s: &Strategies, behind: MergeBehind) {
        self.vc += behind.0 * s.vm_weight;
        self.vm += behind.0;
    }
}

/// What a merge at the vertex a subpath last left would add to its
/// partials, not yet counted.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MergeBehind(f64);

impl MergeBehind {
    /// Carried over a segment to a vertex at cosine `cos`, as `arrive`
    /// carries the partials.
    #[inline]
    pub fn arrive(&mut self, s: &Strategies, cos: f32) {
        self.0 *= 1.0 / s.mis(cos.abs());
    }
}

/// A camera subpath that met an emitter by BSDF sampling (or escaped to
/// the background): `direct_pdf` the density next-event estimation from
/// the previous vertex would have had of the point (per area, per solid
/// angle for the background; times the pick probability), `emission_pdf`
/// the light's density of emitting toward that vertex (times the pick)
/// [report (42)–(43)].
#[inline]
pub fn hit_light(s: &Strategies, camera: &Partials, direct_pdf: f32, emission_pdf: f32) -> f32 {
    weight(s.mis(direct_pdf) * camera.vcm + s.mis(emission_pdf) * camera.vc)
}

/// Next-event estimation from a camera vertex: the BSDF's density of the
/// light's direction `bsdf_pdf` (0 for a delta light) and of the way back
/// `bsdf_reverse_pdf`, the light's `pick` probability, its density `direct_pdf`
/// per solid angle at the vertex (a delta light's d² or 1), its density of
/// emitting toward the vertex `emission_pdf`, and the cosines at the vertex
/// and at the light [report (44)–(45)].
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn direct(
    s: &Strategies,
    camera: &Partials,
    bsdf_pdf: f32,
    bsdf_reverse_pdf: f32,
    pick: f32,
    direct_pdf: f32,
    emission_pdf: f32,
    cos_at_camera: f32,
    cos_at_light: f32,
) -> f32 {
    let light_side = s.mis64(bsdf_pdf as f64 / (pick as f64 * direct_pdf as f64));
    let ratio = emission_pdf as f64 * cos_at_camera as f64 / (direct_pdf as f64 * cos_at_light as f64);
    // A merge at the camera vertex: light came to it straight from the light
    let camera_side = s.mis64(ratio) * (s.vm_weight_at(false) + camera.vcm + camera.vc * s.mis(bsdf_reverse_pdf));
    weight(light_side + camera_side)
}

/// A connection of a light vertex and a camera vertex: the camera BSDF's
/// density of the light vertex per area `camera_pdf_a` and the light BSDF's
/// of the camera vertex `light_pdf_a`; each side's reverse densities per
/// solid angle; whether light came to the light vertex through a specular
/// one [report (40)–(41)].
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn connect(
    s: &Strategies,
    light: &Partials,
    camera: &Partials,
    camera_pdf_a: f32,
    light_pdf_a: f32,
    light_reverse_pdf: f32,
    camera_reverse_pdf: f32,
    light_after_specular: bool,
) -> f32 {
    let light_merge = s.vm_weight_at(light_after_specular);
    let light_side = s.mis(camera_pdf_a) * (light_merge + light.vcm + light.vc * s.mis(light_reverse_pdf));
    // A merge at the camera vertex: light came to it from the light vertex
    let camera_merge = s.vm_weight_at(false);
    let camera_side = s.mis(light_pdf_a) * (camera_merge + camera.vcm + camera.vc * s.mis(camera_reverse_pdf));
    weight(light_side + camera_side)
}

/// A light vertex joined to the camera (t = 1): the camera's density of it
/// per area `camera_pdf_a` (its ray density times cos/d²), the light
/// BSDF's reverse density, whether light came to the vertex through a
/// specular one [report (46)–(47)].
#[inline]
pub fn to_camera(
    s: &Strategies,
    light: &Partials,
    camera_pdf_a: f32,
    light_reverse_pdf: f32,
    after_specular: bool,
) -> f32 {
    let light_side = s.mis64(camera_pdf_a as f64 / s.light_paths as f64)
        * (s.vm_weight_at(after_specular) + light.vcm + light.vc * s.mis(light_reverse_pdf));
    weight(light_side)
}

/// A merge of a light vertex into a camera vertex: the camera BSDF's density
/// of the light's incoming direction `camera_pdf` and of the way back
/// `camera_reverse_pdf` (with the light vertex's continuation) [report (37)–(39)].
#[inline]
pub fn merge(s: &Strategies, light: &Partials, camera: &Partials, camera_pdf: f32, camera_reverse_pdf: f32) -> f32 {
    let light_side = light.vcm * s.vc_weight + light.vm * s.mis(camera_pdf);
    let camera_side = camera.vcm * s.vc_weight + camera.vm * s.mis(camera_reverse_pdf);
    weight(light_side + camera_side)
}
