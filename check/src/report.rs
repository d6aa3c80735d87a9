//! The check's result table: kernels × backends.

use std::collections::BTreeMap;
use strata_kernels::KernelId;

/// What one kernel did on one backend.
#[derive(Clone, Debug, PartialEq)]
pub enum CellResult {
    /// Every output bit-identical to the reference on every case.
    Identical {
        /// Cases run.
        cases: usize,
    },
    /// Float outputs differed, within the kernel's bound.
    WithinUlp {
        /// Cases run.
        cases: usize,
        /// Largest difference seen within the bound.
        max_ulp: u32,
        /// Share of float values beyond the bound (allowed for float-dependent control flow).
        outside_share: f64,
    },
    /// A mismatch or an error, with the first differing element.
    Failed(String),
    /// The backend or the kernel's needs are not available here, and why.
    Unavailable(String),
    /// Not run in the quick check (only `--full` runs it), and why.
    FullRunOnly(String),
}

/// Results of a whole check.
#[derive(Clone, Debug)]
pub struct CheckReport {
    kernels: Vec<KernelId>,
    backends: Vec<String>,
    devices: BTreeMap<String, String>,
    cells: BTreeMap<(KernelId, String), CellResult>,
}

impl CheckReport {
    pub(super) fn new(kernels: Vec<KernelId>, backends: Vec<String>) -> Self {
        Self { kernels, backends, devices: BTreeMap::new(), cells: BTreeMap::new() }
    }

    pub(super) fn set(&mut self, kernel: KernelId, backend: &str, result: CellResult) {
        self.cells.insert((kernel, backend.to_string()), result);
    }

    pub(super) fn set_device(&mut self, backend: &str, device: String) {
        // A slot shared out over several devices (`slot_parts`) names each that differs.
        match self.devices.get_mut(backend) {
            Some(known) if *known != device => *known = format!("{known}; {device}"),
            Some(_) => {}
            None => {
                self.devices.insert(backend.to_string(), device);
            }
        }
    }

    /// The result of `kernel` on `backend`.
    pub fn cell(&self, kernel: KernelId, backend: &str) -> Option<&CellResult> {
        self.cells.get(&(kernel, backend.to_string()))
    }

    /// Every failed cell, as "kernel on backend: reason".
    pub fn failures(&self) -> Vec<String> {
        self.cells
            .iter()
            .filter_map(|((kernel, backend), result)| match result {
                CellResult::Failed(why) => Some(format!("{kernel:?} on {backend}: {why}")),
                _ => None,
            })
            .collect()
    }

    /// The table, for people.
    pub fn render(&self) -> String {
        let mut text = String::new();
        for backend in &self.backends {
            if let Some(device) = self.devices.get(backend) {
                text.push_str(&format!("{device}\n"));
            }
        }
        text.push('\n');
        let name = |k: &KernelId| strata_kernels::Registry::shared().map(|r| r.get(*k).name()).unwrap_or("?");
        let width = self.kernels.iter().map(|k| name(k).len()).max().unwrap_or(6).max(6);
        text.push_str(&format!("{:<width$}", "kernel"));
        for backend in &self.backends {
            text.push_str(&format!(" | {backend:<22}"));
        }
        text.push('\n');
        let mut notes = Vec::new();
        for kernel in &self.kernels {
            text.push_str(&format!("{:<width$}", name(kernel)));
            for backend in &self.backends {
                let cell = match self.cell(*kernel, backend) {
                    Some(CellResult::Identical { cases }) => format!("identical ({cases} cases)"),
                    Some(CellResult::WithinUlp { cases, max_ulp, outside_share }) if *outside_share > 0.0 => {
                        format!("max {max_ulp} ULP, {:.3}% out ({cases})", outside_share * 100.0)
                    }
                    Some(CellResult::WithinUlp { cases, max_ulp, .. }) => {
                        format!("max {max_ulp} ULP ({cases})")
                    }
                    Some(CellResult::Failed(why)) => {
                        notes.push(format!("[{}] {} on {backend}: FAILED: {why}", notes.len() + 1, name(kernel)));
                        format!("FAILED [{}]", notes.len())
                    }
                    Some(CellResult::Unavailable(why)) => {
                        notes.push(format!("[{}] {} on {backend}: unavailable: {why}", notes.len() + 1, name(kernel)));
                        format!("unavailable [{}]", notes.len())
                    }
                    Some(CellResult::FullRunOnly(why)) => {
                        notes.push(format!("[{}] {} on {backend}: --full only: {why}", notes.len() + 1, name(kernel)));
                        format!("--full only [{}]", notes.len())
                    }
                    None => "not run".into(),
                };
                text.push_str(&format!(" | {cell:<22}"));
            }
            text.push('\n');
        }
        if !notes.is_empty() {
            text.push('\n');
            text.push_str(&notes.join("\n"));
            text.push('\n');
        }
        text
    }
}
