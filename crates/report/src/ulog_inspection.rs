//! The text of `learn data inspect FILE.ulg`: [`UlogInspection`], as the `data` crate's
//! inspection of a ULog serialises it, and [`AirframeSection`], the `physics` crate's reading of
//! the log's PX4 airframe parameters (the CLI hands their JSON over; every field is named here,
//! an unknown one is refused), rendered by [`ulog_inspection_text`].

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleInfo {
    pub system: Option<String>,
    pub hardware: Option<String>,
    pub software: Option<String>,
    pub airframe: Option<i64>,
    pub rotor_count: Option<i64>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Airborne {
    pub total_s: f64,
    pub intervals: Vec<[f64; 2]>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepSpread {
    pub median_ms: f64,
    pub p05_ms: f64,
    pub p95_ms: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Gaps {
    pub count: usize,
    pub longest_s: f64,
    pub longest_at_s: f64,
    pub not_increasing: usize,
}

/// How a column's samples relate (see the `data` crate's `ColumnPattern`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ColumnPattern {
    Fresh,
    Held,
    Interpolated,
    Constant,
}

/// Where the key columns' rates are judged (see the `data` crate's `RatesOver`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RatesOver {
    Airborne,
    WholeLog,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnRate {
    pub name: String,
    pub pattern: ColumnPattern,
    pub effective_rate_hz: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TopicInspection {
    pub name: String,
    pub multi_id: u8,
    pub samples: usize,
    pub median_rate_hz: Option<f64>,
    pub steps: Option<StepSpread>,
    pub gaps: Gaps,
    pub columns: Vec<ColumnRate>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DropoutSummary {
    pub count: usize,
    pub total_ms: u64,
    pub longest_ms: u64,
}

/// What a ULog holds for a flight analysis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UlogInspection {
    pub vehicle: VehicleInfo,
    pub start_time_us: u64,
    pub duration_s: f64,
    pub airborne: Option<Airborne>,
    pub rates_over: RatesOver,
    pub topics: Vec<TopicInspection>,
    pub absent_topics: Vec<String>,
    pub other_topics: usize,
    pub dropouts: DropoutSummary,
    pub truncated_at: Option<u64>,
    pub warnings: usize,
    pub timing_limit: Option<TimingLimit>,
}

/// What the motor commands' rate leaves out of reach (see the `data` crate's `TimingLimit`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimingLimit {
    pub topic: String,
    pub command_rate_hz: f64,
    pub shortest_s: f64,
    pub slow: bool,
}

/// A rotor's spin seen from above (see the `physics` crate's `Spin`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Spin {
    #[serde(rename = "ccw")]
    CounterClockwise,
    #[serde(rename = "cw")]
    Clockwise,
}

/// The layout a geometry is (see the `physics` crate's `Layout`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Layout {
    QuadX,
    QuadPlus,
    QuadXUnequalArms,
    HexaX,
    HexaPlus,
    OctoX,
    OctoPlus,
    Coaxial { arms: usize },
    Unrecognised { rotors: usize },
}

/// Which geometry parameters the log's declared defaults show to be set for this vehicle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GeometryDefaults {
    pub declared: bool,
    pub set_for_vehicle: Vec<String>,
    pub builtin_coefficients: bool,
}

/// The vehicle the log's PX4 airframe parameters describe.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AirframeInspection {
    pub airframe: Option<i64>,
    pub rotor_count: usize,
    pub layout: Layout,
    pub arm_lengths_m: Vec<f64>,
    pub moment_ratios_m: Vec<f64>,
    pub spins: Vec<Spin>,
    pub thrust_coefficients_n: Vec<f64>,
    pub thrust_model_factor: f64,
    pub allocation_rank: usize,
    pub defaults: GeometryDefaults,
}

/// The airframe section: read, or why the parameters could not be read.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum AirframeSection {
    Read(AirframeInspection),
    Unreadable(String),
}

impl std::fmt::Display for Layout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::QuadX => write!(f, "quad X"),
            Self::QuadPlus => write!(f, "quad +"),
            Self::QuadXUnequalArms => write!(f, "quad X with unequal front and rear arms"),
            Self::HexaX => write!(f, "hexa X"),
            Self::HexaPlus => write!(f, "hexa +"),
            Self::OctoX => write!(f, "octo X"),
            Self::OctoPlus => write!(f, "octo +"),
            Self::Coaxial { arms } => write!(f, "coaxial: {arms} arms of two rotors"),
            Self::Unrecognised { rotors } => write!(f, "unrecognised: {rotors} rotors"),
        }
    }
}

/// One value when all are equal (to 1e-9), else the list.
fn values(list: &[f64], digits: usize) -> String {
    match list.first() {
        Some(first) if list.iter().all(|v| (v - first).abs() <= 1e-9) => {
            format!("{first:.digits$}")
        }
        _ => list
            .iter()
            .map(|v| format!("{v:.digits$}"))
            .collect::<Vec<_>>()
            .join(", "),
    }
}

fn airframe_text(out: &mut String, section: &AirframeSection) {
    let airframe = match section {
        AirframeSection::Unreadable(message) => {
            let _ = writeln!(out, "airframe:  not read: {message}");
            return;
        }
        AirframeSection::Read(airframe) => airframe,
    };
    let spins: Vec<&str> = airframe
        .spins
        .iter()
        .map(|s| match s {
            Spin::CounterClockwise => "ccw",
            Spin::Clockwise => "cw",
        })
        .collect();
    let _ = writeln!(
        out,
        "airframe:  {} rotors, {}; arms {} m; km {} m ({}); CT {} N; THR_MDL_FAC {}; allocation rank {} of 4",
        airframe.rotor_count,
        airframe.layout,
        values(&airframe.arm_lengths_m, 3),
        values(&airframe.moment_ratios_m, 3),
        spins.join(", "),
        values(&airframe.thrust_coefficients_n, 2),
        airframe.thrust_model_factor,
        airframe.allocation_rank
    );
    let defaults = &airframe.defaults;
    let script = airframe
        .airframe
        .map_or(String::new(), |a| format!(" of SYS_AUTOSTART {a}"));
    if !defaults.declared {
        let _ = writeln!(
            out,
            "           the log declares no parameter defaults: whether CA_ROTOR* were set for this vehicle is unknown"
        );
    } else if defaults.set_for_vehicle.is_empty() {
        let _ = writeln!(
            out,
            "           CA_ROTOR* are the airframe defaults{script}: the geometry may not be this vehicle's"
        );
    } else {
        let _ = writeln!(
            out,
            "           set for this vehicle: {}",
            defaults.set_for_vehicle.join(", ")
        );
    }
    if defaults.declared && defaults.builtin_coefficients {
        let _ = writeln!(
            out,
            "           CT and |KM| are PX4's built-in defaults: thrust and moment coefficients not measured on this vehicle"
        );
    }
}

fn or_unknown(value: &Option<String>) -> &str {
    value.as_deref().unwrap_or("?")
}

/// The terminal text of an inspection: the vehicle, its airframe (when the log has PX4's
/// control-allocation parameters), the times, one block per analysis topic.
pub fn ulog_inspection_text(
    inspection: &UlogInspection,
    airframe: Option<&AirframeSection>,
) -> String {
    let mut out = String::new();
    let vehicle = &inspection.vehicle;
    let number = |v: Option<i64>| v.map_or("?".to_string(), |v| v.to_string());
    let _ = writeln!(
        out,
        "vehicle:   {} on {}, software {}, airframe {}, {} rotors",
        or_unknown(&vehicle.system),
        or_unknown(&vehicle.hardware),
        or_unknown(&vehicle.software),
        number(vehicle.airframe),
        number(vehicle.rotor_count)
    );
    if let Some(section) = airframe {
        airframe_text(&mut out, section);
    }
    let _ = writeln!(
        out,
        "duration:  {:.1} s logged (from {:.3} s on the autopilot's clock)",
        inspection.duration_s,
        inspection.start_time_us as f64 * 1e-6
    );
    let _ = match &inspection.airborne {
        None => writeln!(out, "airborne:  unknown (no vehicle_land_detected)"),
        Some(airborne) => {
            let spans: Vec<String> = airborne
                .intervals
                .iter()
                .map(|[a, b]| format!("{a:.1}-{b:.1} s"))
                .collect();
            writeln!(
                out,
                "airborne:  {:.1} s ({})",
                airborne.total_s,
                if spans.is_empty() {
                    "never".to_string()
                } else {
                    spans.join(", ")
                }
            )
        }
    };
    let dropouts = &inspection.dropouts;
    let _ = writeln!(
        out,
        "dropouts:  {} ({} ms in all, longest {} ms)",
        dropouts.count, dropouts.total_ms, dropouts.longest_ms
    );
    if let Some(offset) = inspection.truncated_at {
        let _ = writeln!(
            out,
            "truncated: the file ends inside a message at byte {offset}; the rest was read"
        );
    }
    let _ = writeln!(
        out,
        "warnings:  {} logged at warning level or worse",
        inspection.warnings
    );
    let over = match inspection.rates_over {
        RatesOver::Airborne => "while airborne",
        RatesOver::WholeLog => "over the whole log",
    };
    let _ = writeln!(
        out,
        "topics:    samples, median rate, steps; how often key columns change {over}"
    );
    for topic in &inspection.topics {
        topic_text(&mut out, topic);
    }
    if !inspection.absent_topics.is_empty() {
        let _ = writeln!(out, "absent:    {}", inspection.absent_topics.join(", "));
    }
    if let Some(limit) = &inspection.timing_limit {
        let _ = write!(
            out,
            "limits:    motor commands new at ~{:.1} Hz ({}): delays and motor lags shorter than \
             ~{:.3} s cannot be identified from this log",
            limit.command_rate_hz, limit.topic, limit.shortest_s
        );
        if limit.slow {
            let _ = write!(
                out,
                " (PX4's high-rate SDLOG_PROFILE logs actuator topics faster)"
            );
        }
        let _ = writeln!(out);
    }
    let _ = writeln!(
        out,
        "others:    {} more topic instances with samples",
        inspection.other_topics
    );
    out
}

fn topic_text(out: &mut String, topic: &TopicInspection) {
    let rate = topic
        .median_rate_hz
        .map_or("?".to_string(), |r| format!("{r:.1}"));
    let _ = write!(
        out,
        "  {}[{}]: {} samples, logged at {rate} Hz",
        topic.name, topic.multi_id, topic.samples
    );
    if let Some(steps) = &topic.steps {
        let _ = write!(
            out,
            "; step {:.1} ms (5-95%: {:.1}-{:.1})",
            steps.median_ms, steps.p05_ms, steps.p95_ms
        );
    }
    let gaps = &topic.gaps;
    if gaps.count > 0 {
        let _ = write!(
            out,
            "; {} gaps, longest {:.2} s at {:.1} s",
            gaps.count, gaps.longest_s, gaps.longest_at_s
        );
    }
    if gaps.not_increasing > 0 {
        let _ = write!(out, "; {} steps not forward in time", gaps.not_increasing);
    }
    let _ = writeln!(out);
    // Columns with the same pattern and about the same rate on one line.
    let mut groups: Vec<(ColumnPattern, f64, Vec<&str>)> = Vec::new();
    for column in &topic.columns {
        let rate = column.effective_rate_hz;
        match groups
            .iter_mut()
            .find(|(p, r, _)| *p == column.pattern && (r - rate).abs() <= 0.1 * r.max(rate))
        {
            Some(group) => group.2.push(&column.name),
            None => groups.push((column.pattern, rate, vec![&column.name])),
        }
    }
    for (pattern, rate, names) in groups {
        let what = match pattern {
            ColumnPattern::Fresh => format!("new every sample (~{rate:.1} Hz)"),
            ColumnPattern::Held => format!("held, changes at ~{rate:.1} Hz"),
            ColumnPattern::Interpolated => format!("interpolated, knots at ~{rate:.1} Hz"),
            ColumnPattern::Constant => "constant".to_string(),
        };
        let _ = writeln!(out, "      {}: {what}", names.join(", "));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn held_and_fresh_columns_are_said_apart() {
        let inspection = UlogInspection {
            vehicle: VehicleInfo {
                system: Some("PX4".into()),
                hardware: Some("PX4_SITL".into()),
                software: None,
                airframe: Some(10017),
                rotor_count: Some(4),
            },
            start_time_us: 2_000_000,
            duration_s: 31.0,
            airborne: Some(Airborne {
                total_s: 11.0,
                intervals: vec![[10.0, 21.0]],
            }),
            rates_over: RatesOver::Airborne,
            topics: vec![TopicInspection {
                name: "actuator_motors".into(),
                multi_id: 0,
                samples: 3100,
                median_rate_hz: Some(100.0),
                steps: Some(StepSpread {
                    median_ms: 10.0,
                    p05_ms: 9.0,
                    p95_ms: 11.0,
                }),
                gaps: Gaps {
                    count: 0,
                    longest_s: 0.011,
                    longest_at_s: 3.0,
                    not_increasing: 0,
                },
                columns: vec![
                    ColumnRate {
                        name: "control[0]".into(),
                        pattern: ColumnPattern::Held,
                        effective_rate_hz: 10.0,
                    },
                    ColumnRate {
                        name: "control[1]".into(),
                        pattern: ColumnPattern::Held,
                        effective_rate_hz: 10.3,
                    },
                ],
            }],
            absent_topics: vec!["wind".into()],
            other_topics: 60,
            dropouts: DropoutSummary {
                count: 0,
                total_ms: 0,
                longest_ms: 0,
            },
            truncated_at: None,
            warnings: 1,
            timing_limit: Some(TimingLimit {
                topic: "actuator_motors[0]".into(),
                command_rate_hz: 10.0,
                shortest_s: 0.1,
                slow: true,
            }),
        };
        let text = ulog_inspection_text(&inspection, None);
        assert!(text.contains("vehicle:   PX4 on PX4_SITL, software ?, airframe 10017, 4 rotors"));
        assert!(text.contains("airborne:  11.0 s (10.0-21.0 s)"));
        assert!(text.contains(
            "  actuator_motors[0]: 3100 samples, logged at 100.0 Hz; step 10.0 ms (5-95%: 9.0-11.0)\n      control[0], control[1]: held, changes at ~10.0 Hz\n"
        ));
        assert!(text.contains("absent:    wind"));
        assert!(text.contains(
            "limits:    motor commands new at ~10.0 Hz (actuator_motors[0]): delays and motor lags \
             shorter than ~0.100 s cannot be identified from this log (PX4's high-rate \
             SDLOG_PROFILE logs actuator topics faster)\n"
        ));
    }

    fn airframe(defaults: GeometryDefaults) -> AirframeSection {
        AirframeSection::Read(AirframeInspection {
            airframe: Some(4001),
            rotor_count: 6,
            layout: Layout::HexaPlus,
            arm_lengths_m: vec![0.25; 6],
            moment_ratios_m: vec![0.016; 6],
            spins: vec![Spin::CounterClockwise, Spin::Clockwise],
            thrust_coefficients_n: vec![6.5, 6.5, 6.5, 6.5, 6.5, 7.0],
            thrust_model_factor: 0.3,
            allocation_rank: 4,
            defaults,
        })
    }

    fn airframe_lines(section: &AirframeSection) -> String {
        let mut out = String::new();
        airframe_text(&mut out, section);
        out
    }

    #[test]
    fn the_airframe_says_what_its_parameters_are_worth() {
        let at_defaults = airframe(GeometryDefaults {
            declared: true,
            set_for_vehicle: vec![],
            builtin_coefficients: true,
        });
        assert_eq!(
            airframe_lines(&at_defaults),
            "airframe:  6 rotors, hexa +; arms 0.250 m; km 0.016 m (ccw, cw); CT 6.50, 6.50, 6.50, 6.50, 6.50, 7.00 N; THR_MDL_FAC 0.3; allocation rank 4 of 4\n           CA_ROTOR* are the airframe defaults of SYS_AUTOSTART 4001: the geometry may not be this vehicle's\n           CT and |KM| are PX4's built-in defaults: thrust and moment coefficients not measured on this vehicle\n"
        );
        let set = airframe(GeometryDefaults {
            declared: true,
            set_for_vehicle: vec!["CA_ROTOR0_PX".into(), "CA_ROTOR5_CT".into()],
            builtin_coefficients: false,
        });
        let text = airframe_lines(&set);
        assert!(
            text.ends_with("\n           set for this vehicle: CA_ROTOR0_PX, CA_ROTOR5_CT\n"),
            "{text}"
        );
        let undeclared = airframe(GeometryDefaults {
            declared: false,
            set_for_vehicle: vec![],
            builtin_coefficients: false,
        });
        assert!(airframe_lines(&undeclared).contains("declares no parameter defaults"));
        let unreadable = AirframeSection::Unreadable("PX4 parameter CA_ROTOR2_PY: missing".into());
        assert_eq!(
            airframe_lines(&unreadable),
            "airframe:  not read: PX4 parameter CA_ROTOR2_PY: missing\n"
        );
    }
}
