//! Every statistical detector fires on the bug it is there to catch: a
//! renderer with a known bug switched on (`gi_studio::faults`, compiled in
//! for tests only) fails it, where the right renderer passes it (each
//! detector's own test file). One test, so no other runs while a bug is
//! switched on in this process.

mod common;

use common::detectors;
use gi_studio::faults::{inject, Fault};

type Detector = (&'static str, fn() -> Result<(), String>);

#[test]
fn each_detector_fires_on_its_injected_bug() {
    let catches: [(Fault, &[Detector]); 7] = [
        (Fault::PhongLobeDim, &[("Phong's closed form", detectors::phong_lobes_reflect_everything)]),
        (Fault::SppmRadiusFixed, &[("SPPM's shrinking radius", detectors::sppm_radius_shrinks)]),
        (Fault::LightPdfOff, &[("MIS under a giant light", detectors::mis_under_a_giant_light_holds_the_closed_form)]),
        (
            Fault::RouletteUndivided,
            &[
                ("the furnace", detectors::path_tracing_holds_the_furnace),
                ("the pixel t-test on lights.ron", || detectors::path_tracing_agrees_with_its_reference("lights")),
            ],
        ),
        (Fault::PhotonPowerHigh, &[("photon mapping's energy", detectors::photon_mapping_holds_path_tracings_energy)]),
        (Fault::RenderPanics, &[("a render's end", detectors::renders_end_and_sessions_go_on)]),
        (Fault::SppmDensityHigh, &[("SPPM in the furnace", detectors::sppm_holds_the_furnace)]),
    ];
    assert_eq!(catches.len(), Fault::ALL.len(), "every fault has its detectors");
    for (fault, detectors) in catches {
        let _bug = inject(fault);
        for (name, detector) in detectors {
            match detector() {
                Err(found) => println!("{fault:?}: {name} fired: {found}"),
                Ok(()) => panic!("{name} did not notice {fault:?}"),
            }
        }
    }
}
