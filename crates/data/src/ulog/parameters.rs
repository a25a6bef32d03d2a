//! A ULog's parameters as plain numbers, for readers that must not depend on the ULog reader
//! (the `physics` crate's vehicle description reads PX4's airframe parameters from it).

use std::collections::BTreeMap;

use ulog::{Log, ParameterNumber};

/// The parameters a log holds, as numbers.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParameterTable {
    /// Each parameter's value at the end of the log (its last change, else its initial value).
    pub values: BTreeMap<String, f64>,
    /// PX4's built-in defaults the log declares; PX4 writes one only for a parameter whose value
    /// differs from it, so a parameter absent here is at its built-in default. `None` when the log
    /// declares no defaults at all (nothing can then be said).
    pub system_defaults: Option<BTreeMap<String, f64>>,
    /// The airframe's defaults (`SYS_AUTOSTART`'s script), written by the same rule.
    pub airframe_defaults: Option<BTreeMap<String, f64>>,
}

/// The parameters of `log` ([`ParameterTable`]).
pub fn parameter_table(log: &Log) -> ParameterTable {
    let parameters = &log.parameters;
    let numbers = |map: &BTreeMap<String, ParameterNumber>| -> BTreeMap<String, f64> {
        map.iter().map(|(k, v)| (k.clone(), v.as_f64())).collect()
    };
    let mut values = numbers(&parameters.initial);
    for change in &parameters.changes {
        values.insert(change.name.clone(), change.value.as_f64());
    }
    let declared =
        !parameters.system_defaults.is_empty() || !parameters.configuration_defaults.is_empty();
    ParameterTable {
        values,
        system_defaults: declared.then(|| numbers(&parameters.system_defaults)),
        airframe_defaults: declared.then(|| numbers(&parameters.configuration_defaults)),
    }
}
