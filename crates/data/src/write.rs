//! Writing flight logs in the Neural-Fly CSV layout (used by the simulator and by tests that make
//! their own small data), and plain numeric tables (a model's predictions).

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

use rotation::Mat3;

use crate::error::{DataError, Result};
use crate::flight_log::FlightLog;

fn list(values: &[f64]) -> String {
    let inner: Vec<String> = values.iter().map(|v| format!("{v:?}")).collect();
    format!("\"[{}]\"", inner.join(", "))
}

fn matrix(m: &Mat3) -> String {
    let rows: Vec<String> = m
        .iter()
        .map(|row| {
            let inner: Vec<String> = row.iter().map(|v| format!("{v:?}")).collect();
            format!("[{}]", inner.join(", "))
        })
        .collect();
    format!("\"[{}]\"", rows.join(", "))
}

impl FlightLog {
    /// Writes the log as a Neural-Fly CSV ([`FlightLog::csv_text`]), creating its folder.
    pub fn write_csv(&self, path: &Path) -> Result<()> {
        let io = |source| DataError::Io {
            path: path.to_path_buf(),
            source,
        };
        let text = self.csv_text();
        if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(parent).map_err(io)?;
        }
        let mut file = std::fs::File::create(path).map_err(io)?;
        file.write_all(text.as_bytes()).map_err(io)
    }

    /// The log as a Neural-Fly CSV (unnamed index column first; optional columns only when
    /// present, the battery voltage last). Numbers are written with full precision, so reading the file back is lossless.
    pub fn csv_text(&self) -> String {
        let mut header = String::from(",t,p");
        let optional = [
            ("p_d", self.position_desired.is_some()),
            ("v_d", self.velocity_desired.is_some()),
            ("q_sp", self.attitude_setpoint.is_some()),
            ("fa", self.residual_force.is_some()),
        ];
        if optional[0].1 {
            header.push_str(",p_d");
        }
        header.push_str(",v");
        if optional[1].1 {
            header.push_str(",v_d");
        }
        header.push_str(",q,R,w,T_sp");
        if optional[2].1 {
            header.push_str(",q_sp");
        }
        header.push_str(",hover_throttle");
        if optional[3].1 {
            header.push_str(",fa");
        }
        header.push_str(",pwm");
        if self.battery_voltage.is_some() {
            header.push_str(",battery_voltage");
        }
        header.push('\n');
        let mut text = header;
        for k in 0..self.len() {
            let _ = write!(text, "{k},{:?},{}", self.time[k], list(&self.position[k]));
            if let Some(pd) = &self.position_desired {
                let _ = write!(text, ",{}", list(&pd[k]));
            }
            let _ = write!(text, ",{}", list(&self.velocity[k]));
            if let Some(vd) = &self.velocity_desired {
                let _ = write!(text, ",{}", list(&vd[k]));
            }
            let _ = write!(
                text,
                ",{},{},{},{}",
                list(&self.quaternion[k]),
                matrix(&self.rotation[k]),
                list(&self.body_rate[k]),
                list(&[self.thrust_setpoint[k]])
            );
            if let Some(qsp) = &self.attitude_setpoint {
                let _ = write!(text, ",{}", list(&qsp[k]));
            }
            let _ = write!(text, ",{}", list(&[self.hover_throttle[k]]));
            if let Some(fa) = &self.residual_force {
                let _ = write!(text, ",{}", list(&fa[k]));
            }
            let _ = write!(text, ",{}", list(self.motor_command.row(k)));
            if let Some(volts) = &self.battery_voltage {
                let _ = write!(text, ",{}", list(&[volts[k]]));
            }
            text.push('\n');
        }
        text
    }
}

/// Writes named numeric columns of equal length as a CSV with a header (names quoted where they
/// need it); numbers with full precision, so reading the file back is lossless.
pub fn write_numeric_csv(path: &Path, names: &[String], columns: &[Vec<f64>]) -> Result<()> {
    let io = |source| DataError::Io {
        path: path.to_path_buf(),
        source,
    };
    let quoted = |name: &String| {
        if name.contains([',', '"', '\n', '\r']) {
            format!("\"{}\"", name.replace('"', "\"\""))
        } else {
            name.clone()
        }
    };
    let mut text = names.iter().map(quoted).collect::<Vec<_>>().join(",");
    text.push('\n');
    let rows = columns.first().map_or(0, Vec::len);
    for row in 0..rows {
        let cells: Vec<String> = columns.iter().map(|c| format!("{:?}", c[row])).collect();
        text.push_str(&cells.join(","));
        text.push('\n');
    }
    let mut file = std::fs::File::create(path).map_err(io)?;
    file.write_all(text.as_bytes()).map_err(io)?;
    Ok(())
}
