//! A sweep's table as Apache Parquet (`sweep.parquet`): the columns of `sweep.csv` with their
//! types (`index`, `steps`, `rhs_evaluations` as 64-bit integers, the variables and quantities as
//! doubles, `status` and `reason` as UTF-8 strings), one row group, and in the file's key-value
//! metadata the sweep's settings as JSON (`chetaev.sweep`: the scene's name, file, hash and
//! parameters, what varies, the seed, the quantities) and the program's version
//! (`chetaev.version`). Written with the `parquet` crate's column writer, uncompressed.

use std::fs::File;
use std::path::Path;
use std::sync::Arc;

use parquet::basic::{LogicalType, Repetition, Type as Physical};
use parquet::data_type::{ByteArray, ByteArrayType, DoubleType, Int64Type};
use parquet::file::metadata::KeyValue;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;

use super::table::Table;
use crate::error::Error;

/// One column's values.
enum Values {
    Long(Vec<i64>),
    Double(Vec<f64>),
    Text(Vec<ByteArray>),
}

/// Writes `table` to `path`.
pub fn write(path: &Path, table: &Table) -> Result<(), Error> {
    let fail = |reason: String| Error::Write {
        path: path.display().to_string(),
        reason,
    };
    let rows = &table.rows;
    let as_long = |f: &dyn Fn(&super::Row) -> usize| {
        Values::Long(
            rows.iter()
                .map(|r| i64::try_from(f(r)).unwrap_or(i64::MAX))
                .collect(),
        )
    };
    let text = |f: &dyn Fn(&super::Row) -> String| {
        Values::Text(
            rows.iter()
                .map(|r| ByteArray::from(f(r).as_str()))
                .collect(),
        )
    };
    let mut columns: Vec<(String, Values)> = vec![("index".to_string(), as_long(&|r| r.index))];
    for (j, v) in table.variables.iter().enumerate() {
        columns.push((
            v.clone(),
            Values::Double(rows.iter().map(|r| r.values[j]).collect()),
        ));
    }
    columns.push(("status".to_string(), text(&|r| r.status.text())));
    for (j, c) in table.columns.iter().enumerate() {
        columns.push((
            c.clone(),
            Values::Double(rows.iter().map(|r| r.quantities[j]).collect()),
        ));
    }
    columns.push(("steps".to_string(), as_long(&|r| r.steps)));
    columns.push((
        "rhs_evaluations".to_string(),
        as_long(&|r| r.rhs_evaluations),
    ));
    columns.push(("reason".to_string(), text(&|r| r.reason.clone())));

    let fields = columns
        .iter()
        .map(|(name, values)| {
            let (physical, logical) = match values {
                Values::Long(_) => (Physical::INT64, None),
                Values::Double(_) => (Physical::DOUBLE, None),
                Values::Text(_) => (Physical::BYTE_ARRAY, Some(LogicalType::String)),
            };
            Type::primitive_type_builder(name, physical)
                .with_repetition(Repetition::REQUIRED)
                .with_logical_type(logical)
                .build()
                .map(Arc::new)
        })
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| fail(e.to_string()))?;
    let schema = Type::group_type_builder("sweep")
        .with_fields(fields)
        .build()
        .map_err(|e| fail(e.to_string()))?;
    let metadata = vec![
        KeyValue::new("chetaev.sweep".to_string(), table.settings.to_string()),
        KeyValue::new(
            "chetaev.version".to_string(),
            env!("CARGO_PKG_VERSION").to_string(),
        ),
    ];
    let props = WriterProperties::builder()
        .set_key_value_metadata(Some(metadata))
        .build();
    let file = File::create(path).map_err(|e| fail(e.to_string()))?;
    let mut writer = SerializedFileWriter::new(file, Arc::new(schema), Arc::new(props))
        .map_err(|e| fail(e.to_string()))?;
    let mut group = writer.next_row_group().map_err(|e| fail(e.to_string()))?;
    let mut next = columns.iter();
    while let Some(mut column) = group.next_column().map_err(|e| fail(e.to_string()))? {
        let Some((_, values)) = next.next() else {
            return Err(fail("more columns in the schema than values".to_string()));
        };
        let written = match values {
            Values::Long(v) => column.typed::<Int64Type>().write_batch(v, None, None),
            Values::Double(v) => column.typed::<DoubleType>().write_batch(v, None, None),
            Values::Text(v) => column.typed::<ByteArrayType>().write_batch(v, None, None),
        };
        written.map_err(|e| fail(e.to_string()))?;
        column.close().map_err(|e| fail(e.to_string()))?;
    }
    group.close().map_err(|e| fail(e.to_string()))?;
    writer.close().map_err(|e| fail(e.to_string()))?;
    Ok(())
}
