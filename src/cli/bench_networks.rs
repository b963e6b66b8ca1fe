//! The networks `psa-esp bench` flies: random networks of the paper's
//! shape, the same in every row.

use anyhow::Result;

use esp_neuroevolution::network::Network;
use esp_neuroevolution::operators::random_genes;
use psa_sim::psa::{INPUT_COUNT, THRUSTER_COUNT};

/// Hidden neurons of the benchmark's networks (the paper's 7-5-4 network).
pub const HIDDEN: usize = 5;

/// Random 7-5-4 networks, weights uniform in (-6, 6) as ESP starts them.
pub fn random_networks(count: u64) -> Result<Vec<Network>> {
    let mut rng = esp_neuroevolution::rng::stream(1, &[]);
    (0..count)
        .map(|_| {
            Ok(Network::from_genes(
                INPUT_COUNT,
                THRUSTER_COUNT,
                random_genes(&mut rng, HIDDEN * (INPUT_COUNT + THRUSTER_COUNT), 6.0),
            )?)
        })
        .collect()
}
