//! Parquet recordings read by column name, whole and in blocks: the values of the same table
//! written as a CSV, whatever the row groups, codec and numeric types; and one-line errors naming
//! the file, row and column for what cannot be read.

use std::path::Path;
use std::sync::Arc;

use data::{DataError, NumericStream, NumericTable, is_parquet, write_numeric_csv};
use parquet::basic::{Compression, Repetition, Type as PhysicalType, ZstdLevel};
use parquet::data_type::{ByteArray, ByteArrayType, DoubleType, FloatType, Int64Type};
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;

/// One column to write: its values as doubles, and how they are stored.
#[derive(Clone)]
enum Column {
    Double(Vec<f64>),
    Float(Vec<f32>),
    Int64(Vec<i64>),
    /// An optional double column: `None` is a null.
    Optional(Vec<Option<f64>>),
    Text(Vec<String>),
}

impl Column {
    fn field(&self, name: &str) -> Arc<Type> {
        let (physical, repetition) = match self {
            Column::Double(_) => (PhysicalType::DOUBLE, Repetition::REQUIRED),
            Column::Float(_) => (PhysicalType::FLOAT, Repetition::REQUIRED),
            Column::Int64(_) => (PhysicalType::INT64, Repetition::REQUIRED),
            Column::Optional(_) => (PhysicalType::DOUBLE, Repetition::OPTIONAL),
            Column::Text(_) => (PhysicalType::BYTE_ARRAY, Repetition::REQUIRED),
        };
        let field = Type::primitive_type_builder(name, physical).with_repetition(repetition);
        Arc::new(field.build().unwrap())
    }
}

/// Writes `columns` to `path` in row groups of `group_rows`, compressed by `codec`.
fn write(path: &Path, columns: &[(&str, Column)], group_rows: usize, codec: Compression) {
    let fields = columns.iter().map(|(name, c)| c.field(name)).collect();
    let schema = Type::group_type_builder("schema")
        .with_fields(fields)
        .build()
        .unwrap();
    let properties = WriterProperties::builder().set_compression(codec).build();
    let file = std::fs::File::create(path).unwrap();
    let mut writer =
        SerializedFileWriter::new(file, Arc::new(schema), Arc::new(properties)).unwrap();
    let rows = match &columns[0].1 {
        Column::Double(v) => v.len(),
        _ => unreachable!("the first column is a double"),
    };
    for start in (0..rows).step_by(group_rows) {
        let end = (start + group_rows).min(rows);
        let mut group = writer.next_row_group().unwrap();
        for (_, column) in columns {
            let mut writer = group.next_column().unwrap().unwrap();
            match column {
                Column::Double(v) => {
                    writer
                        .typed::<DoubleType>()
                        .write_batch(&v[start..end], None, None)
                }
                Column::Float(v) => {
                    writer
                        .typed::<FloatType>()
                        .write_batch(&v[start..end], None, None)
                }
                Column::Int64(v) => {
                    writer
                        .typed::<Int64Type>()
                        .write_batch(&v[start..end], None, None)
                }
                Column::Optional(v) => {
                    let part = &v[start..end];
                    let levels: Vec<i16> = part.iter().map(|x| i16::from(x.is_some())).collect();
                    let present: Vec<f64> = part.iter().flatten().copied().collect();
                    writer
                        .typed::<DoubleType>()
                        .write_batch(&present, Some(&levels), None)
                }
                Column::Text(v) => {
                    let part: Vec<ByteArray> = v[start..end]
                        .iter()
                        .map(|s| ByteArray::from(s.as_str()))
                        .collect();
                    writer
                        .typed::<ByteArrayType>()
                        .write_batch(&part, None, None)
                }
            }
            .unwrap();
            writer.close().unwrap();
        }
        group.close().unwrap();
    }
    writer.close().unwrap();
}

/// A small recording: time, a double, a float and an integer column, and an optional double
/// column without nulls.
fn recording(rows: usize) -> Vec<(&'static str, Column)> {
    let t: Vec<f64> = (0..rows).map(|k| k as f64 * 0.02).collect();
    let x: Vec<f64> = t.iter().map(|t| (1.3 * t).sin() * 1e-3 + t.cos()).collect();
    let f: Vec<f32> = t.iter().map(|t| (0.7 * t).cos() as f32).collect();
    let n: Vec<i64> = (0..rows as i64).map(|k| k * 1_000 - 7).collect();
    let o: Vec<Option<f64>> = x.iter().map(|x| Some(-x / 3.0)).collect();
    vec![
        ("t", Column::Double(t)),
        ("x", Column::Double(x)),
        ("f", Column::Float(f)),
        ("n", Column::Int64(n)),
        ("o", Column::Optional(o)),
    ]
}

/// The columns as doubles.
fn as_doubles(columns: &[(&str, Column)]) -> Vec<Vec<f64>> {
    columns
        .iter()
        .map(|(_, column)| match column {
            Column::Double(v) => v.clone(),
            Column::Float(v) => v.iter().map(|&x| f64::from(x)).collect(),
            Column::Int64(v) => v.iter().map(|&x| x as f64).collect(),
            Column::Optional(v) => v.iter().map(|x| x.unwrap()).collect(),
            Column::Text(_) => unreachable!(),
        })
        .collect()
}

const NAMES: [&str; 5] = ["t", "x", "f", "n", "o"];

#[test]
fn a_parquet_file_reads_as_the_csv_of_its_values_whole_and_in_blocks() {
    let dir = tempfile::tempdir().unwrap();
    let columns = recording(1_003);
    let csv = dir.path().join("r.csv");
    let names: Vec<String> = NAMES.iter().map(|s| s.to_string()).collect();
    write_numeric_csv(&csv, &names, &as_doubles(&columns)).unwrap();
    let expected = NumericTable::read(&csv, &NAMES).unwrap();
    let codecs = [
        Compression::SNAPPY,
        Compression::ZSTD(ZstdLevel::default()),
        Compression::LZ4_RAW,
        Compression::UNCOMPRESSED,
    ];
    for (codec, group_rows) in codecs.into_iter().zip([1_003, 100, 7, 512]) {
        // Named .dat: a Parquet file is known by its content, not its name.
        let path = dir.path().join(format!("r-{group_rows}.dat"));
        write(&path, &columns, group_rows, codec);
        assert!(is_parquet(&path) && !is_parquet(&csv));
        let table = NumericTable::read(&path, &["o", "t", "n"]).unwrap();
        for (name, values) in table.names.iter().zip(&table.columns) {
            let k = NAMES.iter().position(|n| n == name).unwrap();
            assert_eq!(values, &expected.columns[k], "{codec} {name}");
        }
        assert_eq!((table.line(0), table.line(1_002)), (1, 1_003));
        let mut stream = NumericStream::open(&path, &NAMES).unwrap();
        let mut rows = 0;
        while let Some(block) = stream.next_block(333).unwrap() {
            assert_eq!(block.first_row, rows);
            assert_eq!(block.lines[0], rows + 1);
            for (k, values) in block.columns.iter().enumerate() {
                assert_eq!(values[..], expected.columns[k][rows..rows + block.rows()]);
            }
            rows += block.rows();
        }
        assert_eq!(rows, 1_003, "{codec}");
    }
}

/// Many columns of long row groups, decoded in parallel: each column reader reads its own pages
/// (a shared file position would interleave them).
#[test]
fn written_parquet_reads_back_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("w.parquet");
    let names: Vec<String> = (0..8).map(|j| format!("c{j}, {j}")).collect();
    let columns: Vec<Vec<f64>> = (0..8)
        .map(|j| {
            (0..150_000)
                .map(|k| ((k * (j + 1)) as f64).sqrt() * 1e-7 - j as f64)
                .collect()
        })
        .collect();
    data::write_numeric_parquet(&path, &names, &columns).unwrap();
    let reversed: Vec<&str> = names.iter().rev().map(String::as_str).collect();
    let table = NumericTable::read(&path, &reversed).unwrap();
    let expected: Vec<Vec<f64>> = columns.iter().rev().cloned().collect();
    assert!(table.columns == expected);
}

/// The one-line message of reading `columns` of `path` whole, which must equal the streamed
/// reader's.
fn error(path: &Path, columns: &[&str]) -> String {
    let whole = NumericTable::read(path, columns).unwrap_err().to_string();
    let mut stream = match NumericStream::open(path, columns) {
        Ok(stream) => stream,
        Err(error) => {
            assert_eq!(error.to_string(), whole);
            return whole;
        }
    };
    let streamed = loop {
        match stream.next_block(64) {
            Ok(Some(_)) => continue,
            Ok(None) => panic!("{}: read without error", path.display()),
            Err(error) => break error.to_string(),
        }
    };
    assert_eq!(streamed, whole);
    assert!(!whole.contains('\n'), "{whole}");
    whole
}

#[test]
fn what_a_parquet_file_cannot_give_is_named_by_file_row_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.parquet");
    let mut columns = recording(300);
    write(&path, &columns, 100, Compression::SNAPPY);
    let message = error(&path, &["t", "v"]);
    assert!(
        message.contains("bad.parquet: missing column 'v'"),
        "{message}"
    );
    assert!(message.contains("t, x, f, n, o"), "{message}");

    // A null in the third row group, and a NaN after it: the null is named, counted from 1.
    let mut optional: Vec<Option<f64>> = (0..300).map(|k| Some(k as f64)).collect();
    optional[217] = None;
    columns[4].1 = Column::Optional(optional);
    if let Column::Double(x) = &mut columns[1].1 {
        x[250] = f64::NAN;
    }
    write(&path, &columns, 100, Compression::SNAPPY);
    let message = error(&path, &["t", "x", "o"]);
    assert!(
        message.starts_with(&format!("{}:218:o:", path.display())),
        "{message}"
    );
    assert!(message.contains("null"), "{message}");
    let message = error(&path, &["x"]);
    assert!(
        message.contains(":251:x: value is not finite (NaN)"),
        "{message}"
    );

    // Text is not a number.
    columns[4].1 = Column::Text((0..300).map(|k| format!("k{k}")).collect());
    write(&path, &columns, 100, Compression::SNAPPY);
    let message = error(&path, &["t", "o"]);
    assert!(message.contains("o: not a column of numbers"), "{message}");

    // Rows but no row groups' worth of data: empty.
    let empty = dir.path().join("empty.parquet");
    write(&empty, &recording(0), 10, Compression::SNAPPY);
    assert!(matches!(
        NumericTable::read(&empty, &["t"]),
        Err(DataError::Empty { .. })
    ));
}

#[test]
fn a_damaged_parquet_file_is_an_error_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("damaged.parquet");
    write(&path, &recording(2_000), 500, Compression::SNAPPY);
    let bytes = std::fs::read(&path).unwrap();
    // Cut short: the footer is gone, yet the file still begins with the magic bytes.
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let message = error(&path, &["t"]);
    assert!(
        message.starts_with(&path.display().to_string()),
        "{message}"
    );
    // Pages overwritten with noise, the footer intact.
    for start in [8, bytes.len() / 3, bytes.len() / 2] {
        let mut damaged = bytes.clone();
        for (k, byte) in damaged[start..start + 200].iter_mut().enumerate() {
            *byte = (k * 37 % 251) as u8;
        }
        std::fs::write(&path, &damaged).unwrap();
        let read = std::panic::catch_unwind(|| NumericTable::read(&path, &NAMES));
        match read {
            Ok(Ok(_)) | Ok(Err(_)) => {}
            Err(_) => panic!("reading a damaged file panicked (damage at byte {start})"),
        }
    }
}
