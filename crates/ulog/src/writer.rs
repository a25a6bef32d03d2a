//! Writing ULog: a header, the flag bits, one format and one subscription per topic, then the
//! samples in time order. Enough of the format for a simulator to write logs PX4's tools and
//! [`crate::Log::read`] read as they read PX4's own: topics of a `uint64_t timestamp` and `float`
//! fields (scalars or arrays), no parameters, no appended data.

/// A topic to be written: its name and its `float` fields (`q[4]` for an array).
#[derive(Clone, Debug, PartialEq)]
pub struct TopicFormat {
    pub name: String,
    /// Each field's name and length (1 for a scalar).
    pub fields: Vec<(String, usize)>,
}

impl TopicFormat {
    /// The format message's text: `name:uint64_t timestamp;float x;float[4] q;`.
    fn text(&self) -> String {
        let mut text = format!("{}:uint64_t timestamp;", self.name);
        for (field, length) in &self.fields {
            match length {
                1 => text.push_str(&format!("float {field};")),
                n => text.push_str(&format!("float[{n}] {field};")),
            }
        }
        text
    }

    /// How many floats a sample holds.
    pub fn values(&self) -> usize {
        self.fields.iter().map(|(_, n)| n).sum()
    }
}

/// One sample of topic number `topic` (its index among the formats written).
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    pub topic: usize,
    pub time_us: u64,
    /// The fields' values in the format's order, arrays flattened.
    pub values: Vec<f32>,
}

/// The bytes of a ULog file whose logging started at `start_time_us`, with `topics` (each
/// subscribed once, `multi_id` 0) and their `samples`, written in time order (stable for equal
/// times). Fails on a sample of an unknown topic or of the wrong length, or a message over 64 KiB.
pub fn write(
    start_time_us: u64,
    topics: &[TopicFormat],
    samples: &[Sample],
) -> Result<Vec<u8>, String> {
    let mut bytes = b"ULog\x01\x12\x35\x01".to_vec();
    bytes.extend(start_time_us.to_le_bytes());
    // Flag bits: no compatible or incompatible flags, no appended data.
    message(&mut bytes, b'B', &[0u8; 40])?;
    for topic in topics {
        message(&mut bytes, b'F', topic.text().as_bytes())?;
    }
    for (id, topic) in topics.iter().enumerate() {
        let id = u16::try_from(id).map_err(|_| "more than 65536 topics".to_string())?;
        let mut payload = vec![0u8];
        payload.extend(id.to_le_bytes());
        payload.extend(topic.name.as_bytes());
        message(&mut bytes, b'A', &payload)?;
    }
    let mut order: Vec<&Sample> = samples.iter().collect();
    order.sort_by_key(|s| s.time_us);
    for sample in order {
        let topic = topics
            .get(sample.topic)
            .ok_or_else(|| format!("a sample of topic {}, of {}", sample.topic, topics.len()))?;
        if sample.values.len() != topic.values() {
            return Err(format!(
                "{}: a sample of {} values, the format has {}",
                topic.name,
                sample.values.len(),
                topic.values()
            ));
        }
        let mut payload = (sample.topic as u16).to_le_bytes().to_vec();
        payload.extend(sample.time_us.to_le_bytes());
        for v in &sample.values {
            payload.extend(v.to_le_bytes());
        }
        message(&mut bytes, b'D', &payload)?;
    }
    Ok(bytes)
}

/// Appends one message: its payload's size, its kind, its payload.
fn message(bytes: &mut Vec<u8>, kind: u8, payload: &[u8]) -> Result<(), String> {
    let size = u16::try_from(payload.len())
        .map_err(|_| format!("a '{}' message of {} bytes", kind as char, payload.len()))?;
    bytes.extend(size.to_le_bytes());
    bytes.push(kind);
    bytes.extend(payload);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Column, Log};

    /// What is written reads back: the start, each topic's samples at their times, in order.
    #[test]
    fn a_written_log_reads_back() {
        let topics = [
            TopicFormat {
                name: "vehicle_attitude".into(),
                fields: vec![("q".into(), 4)],
            },
            TopicFormat {
                name: "actuator_outputs".into(),
                fields: vec![("noutputs".into(), 1), ("output".into(), 2)],
            },
        ];
        let samples = [
            Sample {
                topic: 1,
                time_us: 2_000,
                values: vec![2.0, 1500.0, 1510.0],
            },
            Sample {
                topic: 0,
                time_us: 1_000,
                values: vec![1.0, 0.0, 0.0, 0.0],
            },
            Sample {
                topic: 0,
                time_us: 3_000,
                values: vec![0.0, 1.0, 0.0, 0.0],
            },
        ];
        let bytes = write(500, &topics, &samples).unwrap();
        let log = Log::parse(&bytes).unwrap();
        assert_eq!(log.start_time_us, 500);
        let attitude = log.topic("vehicle_attitude", 0).unwrap();
        assert_eq!(attitude.timestamps(), [1_000, 3_000]);
        assert_eq!(attitude.column("q[1]"), Some(Column::Float(vec![0.0, 1.0])));
        let outputs = log.topic("actuator_outputs", 0).unwrap();
        assert_eq!(
            outputs.column("output[1]"),
            Some(Column::Float(vec![1510.0]))
        );
        let wrong = Sample {
            topic: 0,
            time_us: 1,
            values: vec![1.0],
        };
        let error = write(0, &topics, &[wrong]).unwrap_err();
        assert!(
            error.contains("vehicle_attitude") && error.contains("1 values"),
            "{error}"
        );
    }
}
