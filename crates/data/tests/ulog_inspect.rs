//! `data::ulog::inspect` on a small synthetic ULog: motor commands logged at 100 Hz but held
//! between updates at 10 Hz, angular rates interpolated between 10 Hz knots, and a land detector
//! that says when the vehicle was airborne.

use data::ulog::{ColumnPattern, RatesOver, inspect};

fn message(bytes: &mut Vec<u8>, kind: u8, payload: &[u8]) {
    bytes.extend(u16::try_from(payload.len()).unwrap().to_le_bytes());
    bytes.push(kind);
    bytes.extend(payload);
}

fn sample(bytes: &mut Vec<u8>, message_id: u16, time_us: u64, values: &[u8]) {
    let mut payload = message_id.to_le_bytes().to_vec();
    payload.extend(time_us.to_le_bytes());
    payload.extend(values);
    message(bytes, b'D', &payload);
}

/// 10 s at 100 Hz; airborne from 2 s to 8 s.
fn synthetic_log() -> Vec<u8> {
    let mut bytes = b"ULog\x01\x12\x35\x01".to_vec();
    bytes.extend(0u64.to_le_bytes());
    for format in [
        "actuator_motors:uint64_t timestamp;float[2] control;",
        "vehicle_angular_velocity:uint64_t timestamp;float[3] xyz;",
        "vehicle_land_detected:uint64_t timestamp;bool landed;uint8_t[7] _padding0;",
    ] {
        message(&mut bytes, b'F', format.as_bytes());
    }
    for (id, name) in [
        (0u16, "actuator_motors"),
        (1, "vehicle_angular_velocity"),
        (2, "vehicle_land_detected"),
    ] {
        let mut payload = vec![0u8];
        payload.extend(id.to_le_bytes());
        payload.extend(name.as_bytes());
        message(&mut bytes, b'A', &payload);
    }
    let knot = |k: u64| ((k as f64) * 0.9).sin() as f32 * 3.0 + 4.0;
    for i in 0..1000u64 {
        let time = 1_000 + i * 10_000;
        if i % 100 == 0 {
            let landed = !(200..800).contains(&i);
            sample(&mut bytes, 2, time, &[u8::from(landed)]);
        }
        let held = knot(i / 10);
        let mut motors = held.to_le_bytes().to_vec();
        motors.extend((held * 0.5).to_le_bytes());
        sample(&mut bytes, 0, time, &motors);
        let (k, f) = (i / 10, (i % 10) as f32 / 10.0);
        let rate = knot(k) + (knot(k + 1) - knot(k)) * f;
        let mut rates = Vec::new();
        for axis in 0..3 {
            rates.extend((rate + axis as f32).to_le_bytes());
        }
        sample(&mut bytes, 1, time, &rates);
    }
    bytes
}

#[test]
fn held_and_interpolated_columns_are_recognised_while_airborne() {
    let log = ulog::Log::parse(&synthetic_log()).unwrap();
    let inspection = inspect(&log);
    let airborne = inspection.airborne.as_ref().unwrap();
    assert_eq!(airborne.intervals, [[2.001, 8.001]]);
    assert_eq!(inspection.rates_over, RatesOver::Airborne);
    let topic = |name: &str| {
        inspection
            .topics
            .iter()
            .find(|t| t.name == name)
            .unwrap_or_else(|| panic!("{name}"))
    };
    let motors = topic("actuator_motors");
    assert_eq!(motors.samples, 1000);
    assert!((motors.median_rate_hz.unwrap() - 100.0).abs() < 1e-9);
    // Motors 2 and 3 are not in the log; the two that are change at 10 Hz.
    assert_eq!(motors.columns.len(), 2);
    for column in &motors.columns {
        assert_eq!(column.pattern, ColumnPattern::Held, "{}", column.name);
        assert!((column.effective_rate_hz - 10.0).abs() < 0.2, "{column:?}");
    }
    let rates = topic("vehicle_angular_velocity");
    for column in &rates.columns {
        assert_eq!(
            column.pattern,
            ColumnPattern::Interpolated,
            "{}",
            column.name
        );
        assert!((column.effective_rate_hz - 10.0).abs() < 1.5, "{column:?}");
    }
    assert_eq!(motors.gaps.count, 0);
    // The motors change at 10 Hz: timing under ~0.1 s is out of this log's reach.
    let limit = inspection.timing_limit.as_ref().unwrap();
    assert_eq!(limit.topic, "actuator_motors[0]");
    assert!(
        (limit.shortest_s - 0.1).abs() < 0.002 && limit.slow,
        "{limit:?}"
    );
    assert!(
        inspection
            .absent_topics
            .contains(&"vehicle_local_position".to_string())
    );
}

/// Columns of three topics on one clock: a topic's value is its latest sample at or before each
/// row (held, never interpolated), and how long the slowest was held is reported.
#[test]
fn columns_of_other_topics_are_held_as_of_the_base_clock() {
    let log = ulog::Log::parse(&synthetic_log()).unwrap();
    let path = std::path::Path::new("synthetic.ulg");
    let columns = [
        "vehicle_angular_velocity.xyz[2]",
        "actuator_motors.control[1]",
        "vehicle_land_detected.landed",
    ];
    let aligned = data::ulog::aligned_table(&log, path, None, &columns).unwrap();
    assert_eq!(aligned.base, "vehicle_angular_velocity[0]");
    assert_eq!(aligned.time.len(), 1000);
    assert!((aligned.time[1] - aligned.time[0] - 0.01).abs() < 1e-12);
    let landed = aligned
        .table
        .column("vehicle_land_detected.landed")
        .unwrap();
    // Landed until 2 s, held between its samples every second.
    assert_eq!(
        (landed[199], landed[200], landed[799], landed[800]),
        (1.0, 0.0, 0.0, 1.0)
    );
    let held: Vec<(&str, f64, f64)> = aligned
        .held
        .iter()
        .map(|h| (h.column.as_str(), h.median_rate_hz, h.longest_hold_s))
        .collect();
    assert_eq!(held[0].0, "actuator_motors.control[1]");
    assert!(
        (held[0].1 - 100.0).abs() < 1e-6 && held[0].2 == 0.0,
        "{held:?}"
    );
    assert!(
        (held[1].1 - 1.0).abs() < 1e-6 && (held[1].2 - 0.99).abs() < 1e-9,
        "{held:?}"
    );
    // On the land detector's clock: ten rows, each the other topics' sample of the same time.
    let slow =
        data::ulog::aligned_table(&log, path, Some("vehicle_land_detected"), &columns).unwrap();
    assert_eq!(slow.time.len(), 10);
    let motors = slow.table.column("actuator_motors.control[1]").unwrap();
    let first = log
        .topic("actuator_motors", 0)
        .unwrap()
        .column_f64("control[1]")
        .unwrap();
    assert_eq!(motors[3], first[300]);
    // A field or topic the log lacks is named with the column.
    let error = data::ulog::aligned_table(&log, path, None, &["actuator_motors.control[7]"])
        .unwrap_err()
        .to_string();
    assert_eq!(
        error,
        "synthetic.ulg: actuator_motors.control[7]: topic actuator_motors has no field 'control[7]'"
    );
    let error = data::ulog::aligned_table(&log, path, None, &["wind.windspeed_north"])
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("the log has no samples of topic wind[0]"),
        "{error}"
    );
}

/// A base clock whose time stamps repeat is refused, naming the sample (a derivative over it would
/// divide by zero).
#[test]
fn a_clock_that_stands_still_is_refused() {
    let mut bytes = b"ULog\x01\x12\x35\x01".to_vec();
    bytes.extend(0u64.to_le_bytes());
    message(&mut bytes, b'F', b"rates:uint64_t timestamp;float x;");
    message(&mut bytes, b'A', b"\x00\x00\x00rates");
    for (time, x) in [(0u64, 1.0f32), (10_000, 2.0), (10_000, 3.0), (20_000, 4.0)] {
        sample(&mut bytes, 0, time, &x.to_le_bytes());
    }
    let log = ulog::Log::parse(&bytes).unwrap();
    let path = std::path::Path::new("still.ulg");
    let error = data::ulog::aligned_table(&log, path, None, &["rates.x"])
        .unwrap_err()
        .to_string();
    assert!(error.starts_with("still.ulg:3:rates[0]:"), "{error}");
}
