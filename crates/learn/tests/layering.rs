//! The crate stays a library of the method on in-memory data: no flight-log crate, CSV reader,
//! data-frame library or file hash among its dependencies, nor among those of the workspace crates
//! it uses (issue 19). Reading flights and CSV tasks and the paper's protocol live in `pipeline`.

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

/// Whether `name` is a crate of this workspace.
fn in_workspace(name: &str) -> bool {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(name)
        .is_dir()
}

#[test]
fn learn_depends_on_no_flight_log_csv_reader_or_data_frame_library() {
    let forbidden = [
        "data", "polars", "csv", "sha2", "glob", "pipeline", "report",
    ];
    let direct = dependencies("learn");
    assert!(
        direct.contains(&"sindy".to_string()) && direct.contains(&"faer".to_string()),
        "{direct:?}"
    );
    let crates = std::iter::once("learn".to_string())
        .chain(direct.iter().filter(|d| in_workspace(d)).cloned());
    for crate_name in crates {
        for dependency in dependencies(&crate_name) {
            assert!(
                !forbidden.contains(&dependency.as_str()),
                "{crate_name} depends on {dependency}"
            );
        }
    }
}
