//! The network file: a versioned JSON document holding a controller's
//! topology, weights, activation, input scaling, the task it was evolved
//! for and its provenance. Saving and loading round-trips exactly.
//!
//! ```json
//! {
//!   "format": "psa-esp-network",
//!   "version": 1,
//!   "topology": { "inputs": 7, "hidden": 5, "outputs": 4 },
//!   "activation": "logistic",
//!   "input_scaling": { "position_scale": 10.0, ... },
//!   "task": 1,
//!   "problem": { the whole problem configuration: body, physics, sensors, tasks, fitness, noise, ... },
//!   "neurons": [ { "weights": [11 numbers: 7 input weights (bias last), 4 output weights], "lesioned": false }, ... ],
//!   "provenance": { "tool_version": "...", "git_commit": "...", "libode_version": "...", ... }
//! }
//! ```

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::sensors::SensorSettings;
use super::settings::PsaSettings;
use super::task::Task;
use crate::provenance::BuildInfo;
use esp_neuroevolution::network::Network;

/// The dotted path (`.sensors.heading_wrap`) of the first leaf of the JSON
/// object `doc` that alone makes it fail to read, laid over the defaults
/// (`parses` says whether a document reads): serde's own errors do not say
/// where an unknown variant or a wrong type was.
pub fn bad_key(doc: &serde_json::Value, parses: &dyn Fn(&serde_json::Value) -> bool) -> Option<String> {
    fn leaves(value: &serde_json::Value, path: &mut Vec<String>, out: &mut Vec<(Vec<String>, serde_json::Value)>) {
        match value.as_object() {
            Some(object) if !object.is_empty() => {
                for (key, child) in object {
                    path.push(key.clone());
                    leaves(child, path, out);
                    path.pop();
                }
            }
            _ => out.push((path.clone(), value.clone())),
        }
    }
    let mut all = Vec::new();
    leaves(doc, &mut Vec::new(), &mut all);
    all.into_iter().find_map(|(path, leaf)| {
        let mut alone = serde_json::Value::Object(serde_json::Map::new());
        let mut at = &mut alone;
        for part in &path {
            at = at
                .as_object_mut()
                .expect("built of objects")
                .entry(part.clone())
                .or_insert_with(|| serde_json::Value::Object(serde_json::Map::new()));
        }
        *at = leaf;
        (!parses(&alone)).then(|| format!(".{}", path.join(".")))
    })
}

/// The `format` field of every network file.
pub const FORMAT: &str = "psa-esp-network";
/// The version this build writes and reads.
pub const VERSION: u32 = 1;
/// The only activation function.
pub const ACTIVATION: &str = "logistic";

/// Why a network file could not be read or written; always names the file.
#[derive(Debug, Error)]
#[error("network file {}: {problem}", path.display())]
pub struct NetworkFileError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong with it.
    pub problem: String,
}

/// Sizes of the network.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Topology {
    /// Inputs, bias included.
    pub inputs: usize,
    /// Hidden neurons.
    pub hidden: usize,
    /// Outputs.
    pub outputs: usize,
}

/// One hidden neuron.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NeuronRecord {
    /// Input weights (bias weight last), then output weights.
    pub weights: Vec<f64>,
    /// Whether the neuron is switched off.
    #[serde(default)]
    pub lesioned: bool,
}

/// The whole file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NetworkFile {
    /// Always [`FORMAT`].
    pub format: String,
    /// Always [`VERSION`] for this build.
    pub version: u32,
    /// Sizes.
    pub topology: Topology,
    /// Always [`ACTIVATION`].
    pub activation: String,
    /// The input scaling the network was evolved with.
    pub input_scaling: SensorSettings,
    /// The task it was evolved for.
    pub task: Task,
    /// The whole problem configuration it was evolved under (body, physics,
    /// sensors, tasks, fitness, noise); absent in files of older builds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub problem: Option<PsaSettings>,
    /// The hidden neurons.
    pub neurons: Vec<NeuronRecord>,
    /// Where it came from: the build, the time, and any further fields
    /// (seed, configuration, fitness) the writer adds.
    pub provenance: serde_json::Map<String, serde_json::Value>,
}

impl NetworkFile {
    /// A file for `network`, stamped with `build` (tool version, git
    /// commit, libode version); `extra` adds provenance fields. No time
    /// stamp, so that the same run always writes the same bytes.
    pub fn new(
        network: &Network,
        task: Task,
        problem: &PsaSettings,
        build: &BuildInfo,
        extra: serde_json::Map<String, serde_json::Value>,
    ) -> NetworkFile {
        let mut provenance = serde_json::Map::new();
        provenance.insert("tool_version".into(), build.tool_version.clone().into());
        provenance.insert("git_commit".into(), build.git_commit.clone().into());
        provenance.insert("libode_version".into(), build.libode_version.clone().into());
        // Places the file in the table of defaults (see `psa::settings::defaults`).
        provenance.insert("defaults".into(), super::settings::defaults::rows().into());
        provenance.extend(extra);
        NetworkFile {
            format: FORMAT.into(),
            version: VERSION,
            topology: Topology {
                inputs: network.inputs(),
                hidden: network.hidden(),
                outputs: network.outputs(),
            },
            activation: ACTIVATION.into(),
            input_scaling: problem.sensors,
            task,
            problem: Some(problem.clone()),
            neurons: (0..network.hidden())
                .map(|k| NeuronRecord {
                    weights: network.neuron(k).to_vec(),
                    lesioned: network.is_lesioned(k),
                })
                .collect(),
            provenance,
        }
    }

    /// The network this file describes, after checking every size and weight.
    pub fn network(&self) -> Result<Network, String> {
        let t = self.topology;
        if self.neurons.len() != t.hidden {
            return Err(format!(
                "topology says {} hidden neurons, the file has {}",
                t.hidden,
                self.neurons.len()
            ));
        }
        let weights: Vec<Vec<f64>> = self.neurons.iter().map(|n| n.weights.clone()).collect();
        let mut network = Network::from_neurons(t.inputs, t.outputs, &weights).map_err(|e| e.to_string())?;
        for (k, n) in self.neurons.iter().enumerate() {
            network.set_lesioned(k, n.lesioned);
        }
        Ok(network)
    }

    /// Writes the file atomically as pretty JSON.
    pub fn save(&self, path: &Path) -> Result<(), NetworkFileError> {
        let fail = |problem: String| NetworkFileError {
            path: path.to_path_buf(),
            problem,
        };
        let mut json = serde_json::to_string_pretty(self).map_err(|e| fail(e.to_string()))?;
        json.push('\n');
        crate::io::write_atomic(path, json.as_bytes()).map_err(|e| fail(format!("{e:#}")))
    }

    /// Reads and checks a file: JSON, format, version, activation, sizes,
    /// finite weights. Returns the file and its network.
    pub fn load(path: &Path) -> Result<(NetworkFile, Network), NetworkFileError> {
        let fail = |problem: String| NetworkFileError {
            path: path.to_path_buf(),
            problem,
        };
        let text = crate::io::read_input_text(path).map_err(|e| fail(format!("cannot read it: {e}")))?;
        let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| fail(format!("not valid JSON: {e}")))?;
        match value.get("format").and_then(|f| f.as_str()) {
            Some(FORMAT) => {}
            Some(other) => return Err(fail(format!("format is {other:?}, expected {FORMAT:?}"))),
            None => {
                return Err(fail(format!(
                    "no \"format\": {FORMAT:?} field; not a psa-esp network file"
                )))
            }
        }
        match value.get("version").and_then(|v| v.as_u64()) {
            Some(v) if v == VERSION as u64 => {}
            Some(v) => {
                return Err(fail(format!("unknown version {v}; this build reads version {VERSION}")));
            }
            None => return Err(fail("no numeric \"version\" field".into())),
        }
        let mut value = value;
        // A file that lacks a setting (written before it existed) gets the
        // value the build that wrote it used (`psa::settings::defaults`).
        let placement =
            super::settings::defaults::Placement::of_json(value.get("provenance").and_then(|p| p.as_object()));
        if let Some(problem) = value.get_mut("problem").filter(|p| p.is_object()) {
            super::settings::defaults::fill(problem, "problem.", &placement)
                .map_err(|e| fail(format!("problem: {e}")))?;
        }
        // The input scaling is the problem's sensors, and lacks what they lack.
        if let Some(scaling) = value.get_mut("input_scaling").filter(|p| p.is_object()) {
            super::settings::defaults::fill(scaling, "problem.sensors.", &placement)
                .map_err(|e| fail(format!("input_scaling: {e}")))?;
        }
        if let Some(problem) = value.get("problem") {
            if let Err(e) = serde_json::from_value::<PsaSettings>(problem.clone()) {
                let key =
                    bad_key(problem, &|v| serde_json::from_value::<PsaSettings>(v.clone()).is_ok()).unwrap_or_default();
                return Err(fail(format!("problem{key}: {e}")));
            }
        }
        let file: NetworkFile = serde_json::from_value(value).map_err(|e| fail(e.to_string()))?;
        if file.activation != ACTIVATION {
            return Err(fail(format!(
                "activation {:?} is not supported (only {ACTIVATION:?})",
                file.activation
            )));
        }
        if let Some(problem) = &file.problem {
            problem
                .validate()
                .map_err(|e| fail(format!("problem configuration: {e:#}")))?;
            if problem.sensors != file.input_scaling {
                return Err(fail("input_scaling differs from problem.sensors".into()));
            }
        }
        let network = file.network().map_err(fail)?;
        Ok((file, network))
    }
}
