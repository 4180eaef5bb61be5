//! Known bugs a test can switch on, to prove that each statistical test
//! fires on a wrong renderer and not only stays quiet on the right one
//! (`tests/injected_bugs.rs`). They exist only with the `faults` feature,
//! which the tests turn on (a dev-dependency of the crate on itself); in any
//! other build `active` is a constant false and the checks compile away.

/// A bug the renderer can be told to have.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Fault {
    /// The Phong lobe's specular part normalised by 0.97: a lobe too dark.
    PhongLobeDim = 1,
    /// SPPM's gather radius never shrinks (α taken as 1).
    SppmRadiusFixed,
    /// An area light's solid-angle pdf, as multiple importance sampling
    /// evaluates it for a BSDF-sampled hit, 1.25 times too high.
    LightPdfOff,
    /// Russian roulette that forgets to divide the survivors by their chance.
    RouletteUndivided,
    /// Photons carry 5% more power than their lights emit.
    PhotonPowerHigh,
    /// A bug that panics while a job is prepared, on a render worker.
    RenderPanics,
    /// SPPM's density estimate (flux over the gather disc's area) 2% too high.
    SppmDensityHigh,
}

impl Fault {
    pub const ALL: [Fault; 7] = [
        Fault::PhongLobeDim,
        Fault::SppmRadiusFixed,
        Fault::LightPdfOff,
        Fault::RouletteUndivided,
        Fault::PhotonPowerHigh,
        Fault::RenderPanics,
        Fault::SppmDensityHigh,
    ];
}

#[cfg(feature = "faults")]
static ACTIVE: std::sync::atomic::AtomicU8 = std::sync::atomic::AtomicU8::new(0);

/// Whether `fault` is switched on.
#[inline(always)]
pub fn active(fault: Fault) -> bool {
    #[cfg(feature = "faults")]
    {
        ACTIVE.load(std::sync::atomic::Ordering::Relaxed) == fault as u8
    }
    #[cfg(not(feature = "faults"))]
    {
        let _ = fault;
        false
    }
}

/// Switch `fault` on until the guard is dropped. One at a time, process
/// wide: the tests that inject run alone in their own binary.
#[cfg(feature = "faults")]
#[must_use]
pub fn inject(fault: Fault) -> Injected {
    ACTIVE.store(fault as u8, std::sync::atomic::Ordering::SeqCst);
    Injected
}

/// While it lives, a fault is switched on.
#[cfg(feature = "faults")]
pub struct Injected;

#[cfg(feature = "faults")]
impl Drop for Injected {
    fn drop(&mut self) {
        ACTIVE.store(0, std::sync::atomic::Ordering::SeqCst);
    }
}
