//! The crate stays a library on matrices: no flight-log crate, CSV reader or data-frame library
//! among its dependencies, nor among those of the workspace crates it uses (issue 19).

use std::path::Path;

/// The names in the `[dependencies]` table of the workspace crate `name`.
fn dependencies(name: &str) -> Vec<String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(name)
        .join("Cargo.toml");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut in_table = false;
    let mut names = Vec::new();
    for line in text.lines().map(str::trim) {
        if line.starts_with('[') {
            in_table = line == "[dependencies]";
        } else if in_table && !line.is_empty() && !line.starts_with('#') {
            let name = line.split(['=', '.', ' ']).next().unwrap_or_default();
            names.push(name.to_string());
        }
    }
    names
}

#[test]
fn sindy_depends_on_no_file_reader_or_data_frame_library() {
    let forbidden = ["data", "polars", "csv", "sha2", "pipeline", "learn"];
    let direct = dependencies("sindy");
    assert!(direct.contains(&"faer".to_string()), "{direct:?}");
    for crate_name in std::iter::once("sindy".to_string()).chain(
        direct
            .iter()
            .filter(|d| {
                Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join("..")
                    .join(d)
                    .is_dir()
            })
            .cloned(),
    ) {
        for dependency in dependencies(&crate_name) {
            assert!(
                !forbidden.contains(&dependency.as_str()),
                "{crate_name} depends on {dependency}"
            );
        }
    }
}
