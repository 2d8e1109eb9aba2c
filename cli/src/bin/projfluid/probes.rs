//! `probes.csv` in the output directory: the readings of the run's probes (the scene key
//! `probes`, or `--probes FILE`), a header `time_s,NAME_m,…,NAME_Pa,…` and one row per reading
//! at every multiple of 1/rate seconds of simulated time, each value printed so that it reads
//! back exactly (`NaN` where a pressure is undefined).

use crate::Failure;
use projfluid::World;
use projfluid::probe::{ProbeReading, ProbeSet};
use projfluid_lab::driver::frame_index;
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The file's name in the output directory.
const FILE: &str = "probes.csv";

/// The probes of a run and the file their readings go to.
pub(crate) struct ProbeLog {
    probes: ProbeSet,
    path: PathBuf,
    file: File,
}

impl ProbeLog {
    /// Starts `probes.csv` in `dir` (created if missing) with its header, replacing any such
    /// file.
    pub(crate) fn create(dir: &Path, probes: ProbeSet) -> Result<Self, Failure> {
        let path = in_dir(dir)?;
        let header = header(&probes);
        Self::open(path, probes, &header)
    }

    /// Continues the `probes.csv` in `dir` that an earlier run wrote up to `world`'s time: its
    /// rows up to that time are kept, later ones dropped; without such a file a new one is
    /// started. Then the probes are read now if a reading is due and was not written. An
    /// existing file with other columns is an error.
    pub(crate) fn resume(dir: &Path, probes: ProbeSet, world: &World) -> Result<Self, Failure> {
        let path = in_dir(dir)?;
        let header = header(&probes);
        let text = match std::fs::read_to_string(&path) {
            Ok(text) => text,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => header.clone(),
            Err(e) => {
                return Err(Failure::Runtime(format!(
                    "cannot read {}: {e}",
                    path.display()
                )));
            }
        };
        let mut lines = text.lines();
        let found = lines.next().unwrap_or_default();
        if found != header.trim_end() {
            return Err(Failure::Input(format!(
                "{} has the columns `{found}`, but the probes now give `{}`: remove it or \
                 choose another --out",
                path.display(),
                header.trim_end()
            )));
        }
        // A reading at time t is kept if it is not later than now by more than the landing
        // tolerance (rows are exact multiples of 1/rate).
        let now = world.time();
        let latest = now + 1e-6 / probes.rate;
        let mut kept = header;
        let mut last = None;
        for (n, line) in lines.enumerate() {
            let time: f64 = (line.split(',').next())
                .and_then(|t| t.parse().ok())
                .ok_or_else(|| {
                    Failure::Input(format!(
                        "{} line {}: not a row of probe readings",
                        path.display(),
                        n + 2
                    ))
                })?;
            if time > latest {
                break;
            }
            kept += line;
            kept.push('\n');
            last = Some(time);
        }
        let mut log = Self::open(path, probes, &kept)?;
        if log.due(world) && last.is_none_or(|t| t < now - 1e-6 / log.probes.rate) {
            log.record(world)?;
        }
        Ok(log)
    }

    /// Writes `text` as the whole file and keeps it open for appending.
    fn open(path: PathBuf, probes: ProbeSet, text: &str) -> Result<Self, Failure> {
        let cannot =
            |e: std::io::Error| Failure::Runtime(format!("cannot write {}: {e}", path.display()));
        let mut file = File::create(&path).map_err(cannot)?;
        file.write_all(text.as_bytes()).map_err(cannot)?;
        Ok(Self { probes, path, file })
    }

    /// Whether a reading falls on `world`'s time: a multiple of 1/rate seconds.
    pub(crate) fn due(&self, world: &World) -> bool {
        frame_index(world.time(), self.probes.rate).is_some()
    }

    /// Reads the probes in `world` and appends the row.
    pub(crate) fn record(&mut self, world: &World) -> Result<(), Failure> {
        let reading = self
            .probes
            .read(world)
            .map_err(|e| Failure::Input(e.to_string()))?;
        self.file
            .write_all(row(&reading).as_bytes())
            .map_err(|e| Failure::Runtime(format!("cannot write {}: {e}", self.path.display())))?;
        Ok(())
    }
}

/// The path of `probes.csv` in `dir`, which is created if missing.
fn in_dir(dir: &Path) -> Result<PathBuf, Failure> {
    std::fs::create_dir_all(dir).map_err(|e| {
        Failure::Runtime(format!(
            "cannot create output directory {}: {e}",
            dir.display()
        ))
    })?;
    Ok(dir.join(FILE))
}

/// The header line: `time_s`, then every probe's column with its unit.
pub(crate) fn header(probes: &ProbeSet) -> String {
    let mut header = String::from("time_s");
    for column in probes.columns() {
        header += &format!(",{column}");
    }
    header + "\n"
}

/// One reading's line: its time, then every value, each printed so that it reads back exactly.
pub(crate) fn row(reading: &ProbeReading) -> String {
    let mut row = reading.time.to_string();
    for value in reading.values() {
        row += &format!(",{value}");
    }
    row + "\n"
}
