//! The reader on small synthetic byte streams built here message by message: each feature of the
//! format, the faults a file can have (one error at the right offset, or a truncated tail kept),
//! and random bytes or mutations of a valid stream, which must never make it panic.

use proptest::prelude::*;
use ulog::{Column, Dropout, Log, LogLevel, ParameterNumber, Problem, Truncation, Value};

/// A ULog stream under construction.
#[derive(Clone)]
struct Stream(Vec<u8>);

impl Stream {
    fn new(start_time_us: u64) -> Self {
        let mut bytes = b"ULog\x01\x12\x35\x01".to_vec();
        bytes.extend(start_time_us.to_le_bytes());
        Self(bytes)
    }

    fn message(mut self, kind: u8, payload: &[u8]) -> Self {
        self.0
            .extend(u16::try_from(payload.len()).unwrap().to_le_bytes());
        self.0.push(kind);
        self.0.extend(payload);
        self
    }

    fn flags(self, incompatible: u8, appended: [u64; 3]) -> Self {
        let mut payload = vec![0u8; 8];
        payload.push(incompatible);
        payload.extend([0u8; 7]);
        for offset in appended {
            payload.extend(offset.to_le_bytes());
        }
        self.message(b'B', &payload)
    }

    fn format(self, text: &str) -> Self {
        self.message(b'F', text.as_bytes())
    }

    fn key_value(prefix: &[u8], key: &str, value: &[u8]) -> Vec<u8> {
        let mut payload = prefix.to_vec();
        payload.push(u8::try_from(key.len()).unwrap());
        payload.extend(key.as_bytes());
        payload.extend(value);
        payload
    }

    fn info(self, key: &str, value: &[u8]) -> Self {
        self.message(b'I', &Self::key_value(&[], key, value))
    }

    fn multi_info(self, continued: bool, key: &str, value: &[u8]) -> Self {
        self.message(b'M', &Self::key_value(&[u8::from(continued)], key, value))
    }

    fn parameter(self, key: &str, value: &[u8]) -> Self {
        self.message(b'P', &Self::key_value(&[], key, value))
    }

    fn default_parameter(self, kinds: u8, key: &str, value: &[u8]) -> Self {
        self.message(b'Q', &Self::key_value(&[kinds], key, value))
    }

    fn subscribe(self, multi_id: u8, message_id: u16, name: &str) -> Self {
        let mut payload = vec![multi_id];
        payload.extend(message_id.to_le_bytes());
        payload.extend(name.as_bytes());
        self.message(b'A', &payload)
    }

    fn data(self, message_id: u16, sample: &[u8]) -> Self {
        let mut payload = message_id.to_le_bytes().to_vec();
        payload.extend(sample);
        self.message(b'D', &payload)
    }

    fn logged(self, level: u8, time_us: u64, text: &str) -> Self {
        let mut payload = vec![level];
        payload.extend(time_us.to_le_bytes());
        payload.extend(text.as_bytes());
        self.message(b'L', &payload)
    }

    fn tagged(self, level: u8, tag: u16, time_us: u64, text: &str) -> Self {
        let mut payload = vec![level];
        payload.extend(tag.to_le_bytes());
        payload.extend(time_us.to_le_bytes());
        payload.extend(text.as_bytes());
        self.message(b'C', &payload)
    }

    fn dropout(self, duration_ms: u16) -> Self {
        self.message(b'O', &duration_ms.to_le_bytes())
    }

    fn len(&self) -> u64 {
        self.0.len() as u64
    }

    fn parse(&self) -> Result<Log, ulog::ParseError> {
        Log::parse(&self.0)
    }
}

/// A `sensor` sample: timestamp, a nested vector array, an i16, padding (at the end, optional).
fn sensor_sample(time_us: u64, value: f32, count: i16, with_padding: bool) -> Vec<u8> {
    let mut sample = time_us.to_le_bytes().to_vec();
    for k in 0..2 {
        sample.extend((value + k as f32).to_le_bytes());
        sample.extend((-value).to_le_bytes());
    }
    sample.extend([7u8, 0, 0, 0]); // a middle padding field's bytes
    sample.extend(count.to_le_bytes());
    if with_padding {
        sample.extend([0u8; 6]);
    }
    sample
}

fn definitions() -> Stream {
    Stream::new(1_000)
        .flags(0, [0; 3])
        .format("vec2:float a;float b;")
        .format(
            "sensor:uint64_t timestamp;vec2[2] v;uint8_t[4] _padding0;int16_t count;uint8_t[6] _padding1;",
        )
        .info("char[3] sys_name", b"PX4")
        .info("uint32_t ver_sw_release", &0x010e_00ffu32.to_le_bytes())
        .multi_info(false, "char[4] boot", b"line")
        .multi_info(true, "char[4] boot", b" two")
        .multi_info(false, "char[5] boot", b"again")
        .parameter("float MPC_THR_HOVER", &0.42f32.to_le_bytes())
        .parameter("int32_t CA_ROTOR_COUNT", &4i32.to_le_bytes())
        .default_parameter(3, "float MPC_THR_HOVER", &0.5f32.to_le_bytes())
        .default_parameter(2, "int32_t CA_ROTOR_COUNT", &6i32.to_le_bytes())
}

fn flight() -> Stream {
    definitions()
        .subscribe(0, 5, "sensor")
        .subscribe(1, 6, "sensor")
        .logged(b'6', 1_500, "armed")
        .data(5, &sensor_sample(2_000, 1.5, -3, true))
        .data(6, &sensor_sample(2_010, 9.0, 4, false))
        .data(5, &sensor_sample(3_000, 2.5, 8, false))
        .dropout(25)
        .parameter("float MPC_THR_HOVER", &0.45f32.to_le_bytes())
        .tagged(b'4', 7, 3_100, "low battery")
        .message(b'S', &[0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12])
}

#[test]
fn a_flight_is_read_whole() {
    let log = flight().parse().unwrap();
    assert_eq!(
        (log.version, log.start_time_us, log.last_time_us),
        (1, 1_000, 3_000)
    );
    assert_eq!(log.info_text("sys_name"), Some("PX4"));
    assert_eq!(log.info["ver_sw_release"], Value::UInt(0x010e_00ff));
    assert_eq!(
        log.multi_info["boot"],
        [
            vec![Value::Text("line".into()), Value::Text(" two".into())],
            vec![Value::Text("again".into())]
        ]
    );
    let parameters = &log.parameters;
    assert_eq!(
        parameters.initial["MPC_THR_HOVER"],
        ParameterNumber::Float(0.42)
    );
    assert_eq!(
        parameters.value("MPC_THR_HOVER"),
        Some(ParameterNumber::Float(0.45))
    );
    assert_eq!(
        parameters.value("CA_ROTOR_COUNT"),
        Some(ParameterNumber::Int(4))
    );
    assert_eq!(parameters.changes.len(), 1);
    assert_eq!(parameters.changes[0].time_us, 3_000);
    assert_eq!(parameters.system_defaults.len(), 1);
    assert_eq!(
        parameters.configuration_defaults["CA_ROTOR_COUNT"],
        ParameterNumber::Int(6)
    );
    assert_eq!(
        log.dropouts,
        [Dropout {
            time_us: 3_000,
            duration_ms: 25
        }]
    );
    assert_eq!(log.messages.len(), 2);
    assert_eq!(
        (
            log.messages[0].level,
            log.messages[0].tag,
            log.messages[0].time_us
        ),
        (LogLevel::Info, None, 1_500)
    );
    assert_eq!(
        (
            log.messages[1].level,
            log.messages[1].tag,
            log.messages[1].text.as_str()
        ),
        (LogLevel::Warning, Some(7), "low battery")
    );
    assert!(log.truncated.is_none());
}

#[test]
fn instances_are_apart_with_their_own_timestamps_and_nested_columns() {
    let log = flight().parse().unwrap();
    let first = log.topic("sensor", 0).unwrap();
    let second = log.topic("sensor", 1).unwrap();
    assert_eq!(first.timestamps(), [2_000, 3_000]);
    assert_eq!(second.timestamps(), [2_010]);
    let names: Vec<&str> = first.fields().iter().map(|f| f.name.as_str()).collect();
    assert_eq!(
        names,
        ["timestamp", "v[0].a", "v[0].b", "v[1].a", "v[1].b", "count"]
    );
    assert_eq!(first.column("v[1].a"), Some(Column::Float(vec![2.5, 3.5])));
    assert_eq!(first.column("count"), Some(Column::Int16(vec![-3, 8])));
    assert_eq!(second.column_f64("v[0].b"), Some(vec![-9.0]));
    assert_eq!(first.column("_padding0[0]"), None);
}

#[test]
fn a_truncated_last_message_is_reported_and_the_rest_kept() {
    let whole = flight().data(5, &sensor_sample(4_000, 3.5, 1, false));
    let cut = whole.0.len() - 5;
    let log = Log::parse(&whole.0[..cut]).unwrap();
    let message_start = flight().len();
    assert_eq!(
        log.truncated,
        Some(Truncation {
            offset: message_start,
            available: cut as u64 - message_start
        })
    );
    assert_eq!(log.topic("sensor", 0).unwrap().len(), 2);
    // A cut inside the 3-byte message header too.
    let log = Log::parse(&whole.0[..message_start as usize + 2]).unwrap();
    assert_eq!(log.truncated.unwrap().available, 2);
}

#[test]
fn a_sample_of_the_wrong_size_is_an_error_at_its_offset() {
    let stream = flight();
    let offset = stream.len();
    let error = stream.data(5, &[0u8; 12]).parse().unwrap_err();
    assert_eq!(error.offset, offset);
    assert_eq!(
        error.problem,
        Problem::DataSize {
            topic: "sensor".into(),
            size: 12,
            min: 30,
            max: 36
        }
    );
    assert_eq!(
        error.to_string(),
        format!("byte {offset}: a 'sensor' sample of 12 bytes, its format needs 30 to 36")
    );
}

#[test]
fn faults_of_the_file_are_errors_naming_them() {
    let problem = |stream: Stream| stream.parse().unwrap_err().problem;
    assert_eq!(
        problem(Stream(b"PK\x03\x04 not a log".to_vec())),
        Problem::NotUlog
    );
    assert_eq!(
        problem(Stream(b"ULog\x01\x12\x35\x01".to_vec())),
        Problem::HeaderTooShort
    );
    assert_eq!(
        problem(flight().data(9, &[0; 34])),
        Problem::UnknownMessageId(9)
    );
    assert_eq!(
        problem(definitions().subscribe(0, 1, "nothing")),
        Problem::UnknownFormat("nothing".into())
    );
    assert!(matches!(
        problem(Stream::new(0).flags(0b10, [0; 3])),
        Problem::IncompatibleFlags(_)
    ));
    assert_eq!(
        problem(definitions().flags(0, [0; 3])),
        Problem::LateFlagBits
    );
    assert_eq!(
        problem(flight().message(0, &[1, 2])),
        Problem::CorruptHeader(0)
    );
    assert_eq!(
        problem(flight().parameter("double X", &1f64.to_le_bytes())),
        Problem::ParameterType {
            key: "X".into(),
            type_name: "double".into()
        }
    );
    assert_eq!(
        problem(flight().info("nospace", b"")),
        Problem::BadKey("nospace".into())
    );
    assert!(matches!(
        problem(flight().message(b'L', &[b'1', 0, 0])),
        Problem::MessageTooShort { kind: 'L', .. }
    ));
    let error = flight()
        .format("t:uint32_t timestamp;")
        .subscribe(0, 9, "t")
        .data(9, &[0; 4]);
    assert_eq!(problem(error), Problem::NoTimestamp("t".into()));
}

#[test]
fn unknown_message_types_are_skipped() {
    let log = flight()
        .message(b'Z', b"from a later format")
        .data(5, &sensor_sample(5_000, 0.0, 0, false))
        .parse()
        .unwrap();
    assert_eq!(log.unknown_messages, 1);
    assert_eq!(log.topic("sensor", 0).unwrap().len(), 3);
}

#[test]
fn appended_data_is_read_from_its_offset_as_pyulog_does() {
    // The flag bits name where the appended part starts; a message the crash cut short before it
    // is dropped, as pyulog drops it.
    let head = Stream::new(0).flags(1, [0; 3]);
    let flags_at = 16 + 3 + 16;
    let body = Stream(head.0.clone())
        .format("vec2:float a;float b;")
        .format(
            "sensor:uint64_t timestamp;vec2[2] v;uint8_t[4] _padding0;int16_t count;uint8_t[6] _padding1;",
        )
        .subscribe(0, 5, "sensor")
        .data(5, &sensor_sample(2_000, 1.0, 1, false));
    let mut bytes = body.0.clone();
    bytes.extend(
        &Stream(Vec::new())
            .data(5, &sensor_sample(2_500, 9.0, 9, false))
            .0[..10],
    );
    let appended_at = bytes.len() as u64;
    let mut bytes = Stream(bytes)
        .data(5, &sensor_sample(3_000, 2.0, 2, false))
        .0;
    bytes[flags_at..flags_at + 8].copy_from_slice(&appended_at.to_le_bytes());
    let log = Log::parse(&bytes).unwrap();
    assert!(log.appended_data);
    assert!(log.truncated.is_none());
    assert_eq!(log.topic("sensor", 0).unwrap().timestamps(), [2_000, 3_000]);
    // An offset beyond the file is an error.
    let beyond = bytes.len() as u64 + 1;
    bytes[flags_at..flags_at + 8].copy_from_slice(&beyond.to_le_bytes());
    assert!(matches!(
        Log::parse(&bytes).unwrap_err().problem,
        Problem::BadAppendedOffset { .. }
    ));
}

#[test]
fn a_file_error_names_the_file_and_offset_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.ulg");
    let stream = flight();
    let offset = stream.len();
    std::fs::write(&path, &stream.data(5, &[0u8; 3]).0).unwrap();
    let message = Log::read(&path).unwrap_err().to_string();
    assert_eq!(
        message,
        format!(
            "{}: byte {offset}: a 'sensor' sample of 3 bytes, its format needs 30 to 36",
            path.display()
        )
    );
    assert!(!message.contains('\n'));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let _ = Log::parse(&bytes);
        let mut with_magic = b"ULog\x01\x12\x35\x01".to_vec();
        with_magic.extend(&bytes);
        let _ = Log::parse(&with_magic);
    }

    #[test]
    fn mutations_of_a_valid_log_never_panic(
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
        cut in any::<prop::sample::Index>(),
    ) {
        let mut bytes = flight().0;
        for (at, byte) in edits {
            let at = at.index(bytes.len());
            bytes[at] = byte;
        }
        let cut = cut.index(bytes.len() + 1);
        if let Ok(log) = Log::parse(&bytes[..cut]) {
            for topic in &log.topics {
                for field in topic.fields() {
                    let column = topic.column(&field.name).unwrap();
                    prop_assert_eq!(column.len(), topic.len());
                }
            }
        }
    }
}
