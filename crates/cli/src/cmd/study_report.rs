//! `dualsplit report --from DIR`: a study's page from the results its jobs stored. Never
//! simulates: missing or invalid entries are listed (with the `--array` ranges to
//! resubmit) and the exit status is nonzero until every entry has a result.

use dualsplit_report::study::page::{assemble, write_study};
use std::path::Path;
use std::process::ExitCode;

/// Assembles the study in `dir` into `out` (default `dir/report`).
pub fn run(dir: &Path, out: Option<&Path>) -> anyhow::Result<ExitCode> {
    let data = assemble(dir)?;
    let out = out.map_or_else(|| dir.join("report"), Path::to_path_buf);
    crate::output::prepare_dir(&out, "--out")?;
    let files = write_study(&data, &out)?;
    let charts = files
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "svg"))
        .count();
    outln!(
        "wrote {} ({} of {} results, {charts} sweep charts)",
        out.join("index.html").display(),
        data.rows.len(),
        data.planned
    );
    if data.complete() {
        return Ok(ExitCode::SUCCESS);
    }
    for (i, d) in &data.descriptions {
        match data.invalid.iter().find(|(j, _)| j == i) {
            Some((_, why)) => eprintln!("invalid: {d}: {why}"),
            None => eprintln!("missing: {d}"),
        }
    }
    eprintln!(
        "{} of {} entries have no valid result; run them (run-job DIR INDEX, or resubmit \
         with --array={}), then report --from again",
        data.missing.len() + data.invalid.len(),
        data.planned,
        data.todo_ranges()
    );
    Ok(ExitCode::from(2))
}
