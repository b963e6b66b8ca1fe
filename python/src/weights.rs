//! Networks to and from NumPy arrays, in the documented layout of a
//! network's weights (docs/file-formats.md, "Network files"): hidden
//! neuron after hidden neuron, each its input weights (bias last), then
//! its output weights; 7 + 4 = 11 for the PSA.

use esp_neuroevolution::network::{Network, NetworkSet};
use numpy::ndarray::{Array2, Array3};
use numpy::{
    dtype, IntoPyArray, PyArray2, PyArray3, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

use crate::config::type_name;

/// `value` as a float64 array, or a `TypeError` naming what it is. A
/// float32 or float16 array (evosax's and EvoTorch's default dtype) is
/// converted: every such number is a float64 exactly. Anything else NumPy
/// reads as an array (a list of equal-length arrays, as pycma's `ask()`
/// gives, or another library's tensor) is taken as `numpy.asarray` reads
/// it, under the same rule.
pub fn float_array<'py>(value: &Bound<'py, PyAny>, what: &str) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let py = value.py();
    if value.cast::<PyUntypedArray>().is_err() {
        let hint = "(a NumPy array of float64, or a sequence of equal-length float arrays)";
        let read = py.import("numpy")?.call_method1("asarray", (value,)).map_err(|e| {
            PyValueError::new_err(format!(
                "{what} must be an array {hint}; NumPy cannot read {} as one: {}",
                type_name(value),
                e.value(py)
            ))
        })?;
        let untyped = read.cast::<PyUntypedArray>()?;
        if untyped.dtype().kind() != b'f' {
            return Err(PyTypeError::new_err(format!(
                "{what} must be an array {hint}, got {} (of {})",
                type_name(value),
                untyped.dtype()
            )));
        }
        return float_array(&read, what);
    }
    let untyped = value.cast::<PyUntypedArray>()?;
    let dtype_of = untyped.dtype();
    if dtype_of.is_equiv_to(&dtype::<f64>(py)) {
        return Ok(value.cast::<PyArrayDyn<f64>>()?.clone());
    }
    let exact = dtype_of.is_equiv_to(&dtype::<f32>(py)) || dtype_of.kind() == b'f' && dtype_of.itemsize() < 8;
    if !exact {
        return Err(PyTypeError::new_err(format!(
            "{what} must be a NumPy array of float64 (or float32, converted exactly), got dtype {dtype_of} (convert it with .astype(numpy.float64))"
        )));
    }
    Ok(value
        .call_method1("astype", ("float64",))?
        .cast_into::<PyArrayDyn<f64>>()?)
}

/// The networks of `weights`, an array of shape (networks, hidden,
/// inputs + outputs) or (networks, hidden x (inputs + outputs)), with
/// `lesioned` (networks, hidden) where given. One network of shape
/// (hidden, genes) or (hidden x genes) is taken with `single`.
pub fn networks_from(
    weights: &Bound<'_, PyAny>,
    inputs: usize,
    outputs: usize,
    lesioned: Option<&Bound<'_, PyAny>>,
    single: bool,
) -> PyResult<Vec<Network>> {
    let array = float_array(weights, "weights")?;
    let readonly = array.try_readonly().map_err(|e| PyValueError::new_err(e.to_string()))?;
    let view = readonly.as_array();
    let per = inputs + outputs;
    let shape = view.shape().to_vec();
    let layout = if single {
        "(hidden, genes) or (hidden * genes,)"
    } else {
        "(networks, hidden, genes) or (networks, hidden * genes)"
    };
    let expected = |problem: &str| {
        PyValueError::new_err(format!(
            "weights of shape {shape:?}: {problem}; expected {layout} with {per} genes per hidden neuron \
             ({inputs} input weights, bias last, then {outputs} output weights)"
        ))
    };
    let dims = if single { shape.len() + 1 } else { shape.len() };
    let (count, hidden) = match (dims, &shape[..]) {
        (3, [n, h, g]) if !single => {
            if *g != per {
                return Err(expected(&format!("{g} genes per hidden neuron")));
            }
            (*n, *h)
        }
        (3, [h, g]) => {
            if *g != per {
                return Err(expected(&format!("{g} genes per hidden neuron")));
            }
            (1, *h)
        }
        (2, [n, flat]) if !single => {
            if flat % per != 0 {
                return Err(expected(&format!(
                    "{flat} weights per network are not whole hidden neurons"
                )));
            }
            (*n, flat / per)
        }
        (2, [flat]) => {
            if flat % per != 0 {
                return Err(expected(&format!("{flat} weights are not whole hidden neurons")));
            }
            (1, flat / per)
        }
        _ => return Err(expected(&format!("{} dimensions", shape.len()))),
    };
    if hidden == 0 {
        return Err(expected("no hidden neuron (a network has at least one)"));
    }
    let flags = match lesioned {
        None => None,
        Some(mask) if mask.is_none() => None,
        Some(mask) => Some(lesion_flags(mask, count, hidden, single)?),
    };
    let genes: Vec<f64> = view.iter().copied().collect();
    let per_network = hidden * per;
    (0..count)
        .map(|j| {
            let mut network =
                Network::from_genes(inputs, outputs, genes[j * per_network..(j + 1) * per_network].to_vec()).map_err(
                    |e| {
                        if single {
                            PyValueError::new_err(format!("weights: {e}"))
                        } else {
                            PyValueError::new_err(format!("weights of network {j}: {e}"))
                        }
                    },
                )?;
            if let Some(flags) = &flags {
                for k in 0..hidden {
                    network.set_lesioned(k, flags[j * hidden + k]);
                }
            }
            Ok(network)
        })
        .collect()
}

/// The lesion flags of `count` networks of `hidden` neurons, row by row.
fn lesion_flags(mask: &Bound<'_, PyAny>, count: usize, hidden: usize, single: bool) -> PyResult<Vec<bool>> {
    let array = mask.cast::<numpy::PyArrayDyn<bool>>().map_err(|_| {
        PyTypeError::new_err(format!(
            "lesioned must be a NumPy array of bool, got {}",
            type_name(mask)
        ))
    })?;
    let readonly = array.try_readonly().map_err(|e| PyValueError::new_err(e.to_string()))?;
    let view = readonly.as_array();
    let wanted: Vec<usize> = if single { vec![hidden] } else { vec![count, hidden] };
    if view.shape() != wanted.as_slice() {
        return Err(PyValueError::new_err(format!(
            "lesioned of shape {:?} does not fit the weights: expected {wanted:?}",
            view.shape()
        )));
    }
    Ok(view.iter().copied().collect())
}

/// The genes of networks `0..set.len()` of `set` (all of `hidden` neurons)
/// as an array (networks, hidden, genes), a lesioned neuron's genes as
/// zeros (it then adds exactly nothing to any output, as a lesioned neuron
/// does), and the lesion flags (networks, hidden).
pub fn arrays_of<'py, S: NetworkSet + ?Sized>(
    py: Python<'py>,
    set: &S,
) -> (Bound<'py, PyArray3<f64>>, Bound<'py, PyArray2<bool>>) {
    let count = set.len();
    let hidden = (0..count).map(|j| set.hidden(j)).max().unwrap_or(0);
    let per = if count == 0 {
        0
    } else {
        let (inputs, outputs) = set.shape(0);
        inputs + outputs
    };
    let mut genes = Array3::<f64>::zeros((count, hidden, per));
    let mut flags = Array2::<bool>::from_elem((count, hidden), false);
    for j in 0..count {
        for k in 0..set.hidden(j) {
            if set.is_lesioned(j, k) {
                flags[[j, k]] = true;
                continue;
            }
            for (g, &w) in set.neuron(j, k).iter().enumerate() {
                genes[[j, k, g]] = w;
            }
        }
    }
    (genes.into_pyarray(py), flags.into_pyarray(py))
}

/// One network's genes (hidden, genes) and lesion flags (hidden), its
/// lesioned neurons' genes kept as they are.
pub fn network_arrays<'py>(
    py: Python<'py>,
    network: &Network,
) -> (Bound<'py, PyArray2<f64>>, Bound<'py, numpy::PyArray1<bool>>) {
    let genes = Array2::from_shape_vec((network.hidden(), network.genes_per_neuron()), network.genes().to_vec())
        .expect("a network's genes are whole neurons");
    let flags: Vec<bool> = (0..network.hidden()).map(|k| network.is_lesioned(k)).collect();
    (genes.into_pyarray(py), flags.into_pyarray(py))
}
