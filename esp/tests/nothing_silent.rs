//! Nothing silent in the search crate: a clone of a run is a
//! run of its own, a search read from JSON is checked as one built in
//! code, and the seed is written where JSON tools keep every digit.

use esp_neuroevolution::network::NetworkSet;
use esp_neuroevolution::{AskTell, Esp, EspSettings, HillClimb, HillClimbSettings, RunError};

#[allow(dead_code)] // this file uses a share of the helpers
mod common;

use common::small;

#[test]
fn a_clone_of_a_run_has_a_ticket_identity_of_its_own() {
    let esp = Esp::new(small(EspSettings::hoverstad()), 3).unwrap();
    let mut original = esp.start(2, 1).unwrap();
    let ticket = {
        let asked = original.ask().unwrap().expect("a first ask");
        asked.ticket()
    };
    let mut clone = original.clone();
    let fitness = vec![0.0; clone.ask().unwrap().expect("the clone's ask").len()];
    // The original's ticket is foreign to the clone, and the clone's to the original.
    assert!(matches!(clone.tell(ticket, &fitness), Err(RunError::ForeignTicket)));
    let clone_ticket = clone.ask().unwrap().unwrap().ticket();
    assert!(matches!(
        original.tell(clone_ticket, &fitness),
        Err(RunError::ForeignTicket)
    ));
    // Each takes its own.
    assert!(original.tell(ticket, &fitness).is_ok());
    assert!(clone.tell(clone_ticket, &fitness).is_ok());
}

#[test]
fn a_search_read_from_json_is_checked_as_one_built_in_code() {
    let esp = Esp::new(small(EspSettings::hoverstad()), 5).unwrap();
    let good = serde_json::to_value(&esp).unwrap();
    assert_eq!(serde_json::from_value::<Esp>(good.clone()).unwrap(), esp);
    for (key, value) in [("subpop_size", 0), ("initial_hidden", 0), ("trials_per_neuron", 0)] {
        let mut bad = good.clone();
        bad["settings"][key] = value.into();
        let err = serde_json::from_value::<Esp>(bad).unwrap_err().to_string();
        assert!(err.contains(key), "{key}: {err}");
    }
    let climb = HillClimb::new(HillClimbSettings::default(), 5).unwrap();
    let good = serde_json::to_value(&climb).unwrap();
    assert_eq!(serde_json::from_value::<HillClimb>(good.clone()).unwrap(), climb);
    let mut bad = good;
    bad["settings"]["candidates"] = 0.into();
    let err = serde_json::from_value::<HillClimb>(bad).unwrap_err().to_string();
    assert!(err.contains("candidates"), "{err}");
}

#[test]
fn the_seed_is_written_as_a_string_and_read_from_either_form() {
    let seed = (1u64 << 60) + 1;
    let esp = Esp::new(small(EspSettings::hoverstad()), seed).unwrap();
    let json = serde_json::to_value(&esp).unwrap();
    assert_eq!(json["seed"], serde_json::json!(seed.to_string()));
    let mut number = json.clone();
    number["seed"] = seed.into();
    assert_eq!(serde_json::from_value::<Esp>(number).unwrap().seed(), seed);
    // A saved run (a lockstep grid's checkpoint.json) likewise.
    let run = esp.start(2, 1).unwrap();
    let saved = serde_json::to_value(&run).unwrap();
    assert_eq!(saved["search"]["seed"], serde_json::json!(seed.to_string()));
    let climb = HillClimb::new(HillClimbSettings::default(), seed).unwrap();
    assert_eq!(
        serde_json::to_value(&climb).unwrap()["seed"],
        serde_json::json!(seed.to_string())
    );
}
