//! Omni- and unidirectional compression at constant wall speed, measured every
//! `average_steps` steps: wall pressures averaged over those steps, filling factor, contacts and
//! the energy channels.

use super::measure::filling_factor;
use super::setup::{build_sample, build_walls, stored_monomers, SetupError, TOP_WALL};
use crate::binary::{DecodeError, Decoder, Encoder};
use crate::config::{Config, ExperimentKind};
use crate::engine::{Engine, EngineError};
use crate::model::ContactLaw;
use crate::sample::Footprint;
use crate::state::rows::{RowMeasures, RowRequest, Slabs};
use crate::state::{EnergyReport, Monomers, State, Wall};
use std::fmt;

/// One measurement row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Row {
    pub step: u64,
    pub time: f64,
    /// Distance between the bottom and top wall planes [cm].
    pub wall_gap: f64,
    /// Cross-section used for φ and P [cm²]: the box base, or the projected area (uni).
    pub area: f64,
    pub phi: f64,
    /// Mean pressure on the top and bottom wall over the last `average_steps` steps [Pa].
    pub p_top: f64,
    pub p_bottom: f64,
    pub contacts: usize,
    pub wall_contacts: usize,
    pub energy: EnergyReport,
}

impl Row {
    pub const HEADER: [&'static str; 22] = [
        "step",
        "time_s",
        "wall_gap_um",
        "area_um2",
        "phi",
        "p_top_pa",
        "p_bottom_pa",
        "contacts",
        "wall_contacts",
        "e_kinetic_erg",
        "e_rotational_erg",
        "e_normal_erg",
        "e_tangential_erg",
        "d_breaking_erg",
        "d_forming_erg",
        "d_damping_erg",
        "d_rolling_erg",
        "d_sliding_erg",
        "d_twisting_erg",
        "d_walls_erg",
        "wall_work_erg",
        "energy_balance_erg",
    ];

    pub fn values(&self) -> Vec<f64> {
        let e = &self.energy;
        let d = &e.dissipated;
        vec![
            self.step as f64,
            self.time,
            self.wall_gap * 1e4,
            self.area * 1e8,
            self.phi,
            self.p_top,
            self.p_bottom,
            self.contacts as f64,
            self.wall_contacts as f64,
            e.kinetic,
            e.rotational,
            e.normal_potential,
            e.tangential_potential,
            d.breaking,
            d.forming,
            d.damping,
            d.rolling,
            d.sliding,
            d.twisting,
            d.walls,
            e.wall_work,
            e.balance(),
        ]
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    FillingFactor,
    Pressure,
    MaxSteps,
}

impl fmt::Display for StopReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            StopReason::FillingFactor => "filling factor reached phi_stop",
            StopReason::Pressure => "pressure reached pressure_stop_pa",
            StopReason::MaxSteps => "max_steps reached",
        })
    }
}

#[derive(Debug)]
pub enum RunError {
    Setup(SetupError),
    Engine(EngineError),
    Output(String),
    /// Stopped on request (SIGINT/SIGTERM) after writing a checkpoint.
    Interrupted {
        checkpoint: std::path::PathBuf,
    },
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RunError::Setup(e) => write!(f, "{e}"),
            RunError::Engine(e) => write!(f, "{e}"),
            RunError::Output(e) => write!(f, "{e}"),
            RunError::Interrupted { checkpoint } => write!(
                f,
                "interrupted; continue with: dustdem resume {}",
                checkpoint.display()
            ),
        }
    }
}

impl std::error::Error for RunError {}

impl From<EngineError> for RunError {
    fn from(e: EngineError) -> Self {
        RunError::Engine(e)
    }
}

/// What the run reports as it goes.
pub enum Event<'a, E: Engine> {
    Row(&'a Row),
    /// Filling-factor profile in slabs one diameter thick: (slab centre height [cm], φ).
    Profile(&'a Row, &'a [(f64, f64)]),
    /// Everything of a row has been reported and the run will continue: a point where the
    /// state can be checkpointed (the report may return an error to stop here).
    RowDone(&'a Compression<E>),
}

/// A compression run on engine `E`. As a checkpoint holds it, before an engine continues it,
/// `E` is the bare [`State`] ([`Compression::decode_state`], then [`Compression::map_engine`]).
pub struct Compression<E> {
    pub kind: ExperimentKind,
    pub engine: E,
    /// Base of the box or cylinder the sample was made in.
    pub footprint: Footprint,
    average_steps: u64,
    phi_stop: f64,
    pressure_stop: f64,
    max_steps: u64,
    profile_every: u64,
    rows: u64,
}

impl Compression<State> {
    /// A run as [`Compression::encode_state`] wrote it, under `config` (the one the checkpoint
    /// carries), on no engine yet: [`Compression::map_engine`] continues it on one.
    pub fn decode_state(config: &Config, d: &mut Decoder) -> Result<Self, DecodeError> {
        let kind = d.u32("footprint")?;
        let size = d.f64("footprint")?;
        let footprint = match kind {
            0 => Footprint::Box { side: size },
            1 => Footprint::Cylinder { radius: size },
            k => {
                return Err(DecodeError {
                    what: "footprint".into(),
                    offset: d.offset,
                    problem: format!("unknown footprint kind {k}"),
                })
            }
        };
        let rows = d.u64("rows")?;
        let engine = State::decode(config.contact_law(), d)?;
        let e = &config.experiment;
        Ok(Compression {
            kind: e.kind,
            engine,
            footprint,
            average_steps: e.average_steps,
            phi_stop: e.phi_stop,
            pressure_stop: e.pressure_stop_pa,
            max_steps: e.max_steps,
            profile_every: e.profile_every_rows,
            rows,
        })
    }
}

impl<E> Compression<E> {
    /// The same run continued on another engine made from this one's (a resumed checkpoint
    /// moving to the GPU, for instance).
    pub fn map_engine<F: Engine>(
        self,
        convert: impl FnOnce(E) -> Result<F, EngineError>,
    ) -> Result<Compression<F>, RunError> {
        Ok(Compression {
            kind: self.kind,
            engine: convert(self.engine)?,
            footprint: self.footprint,
            average_steps: self.average_steps,
            phi_stop: self.phi_stop,
            pressure_stop: self.pressure_stop,
            max_steps: self.max_steps,
            profile_every: self.profile_every,
            rows: self.rows,
        })
    }
}

impl<E: Engine> Compression<E> {
    /// The run's state for a checkpoint: footprint, rows reported, engine.
    pub fn encode_state(&self, e: &mut Encoder) {
        match self.footprint {
            Footprint::Box { side } => {
                e.u32(0);
                e.f64(side);
            }
            Footprint::Cylinder { radius } => {
                e.u32(1);
                e.f64(radius);
            }
        }
        e.u64(self.rows);
        self.engine.state().encode(e);
    }

    /// The compression a config describes, on the engine `build` makes of its initial state.
    pub fn with_engine(
        config: &Config,
        build: impl FnOnce(ContactLaw, f64, Monomers, Vec<Wall>, usize, usize) -> Result<E, EngineError>,
    ) -> Result<Self, RunError> {
        let law = config.contact_law();
        let sample = build_sample(config, &law).map_err(RunError::Setup)?;
        let walls = build_walls(config, &law, &sample).map_err(RunError::Setup)?;
        let mut engine = build(
            law,
            config.dt(),
            stored_monomers(config, &sample),
            walls,
            config.integration.pair_slots,
            config.integration.wall_slots,
        )?;
        if !config.output.tally_corrections {
            engine.stop_tallying_corrections();
        }
        let e = &config.experiment;
        Ok(Compression {
            kind: e.kind,
            engine,
            footprint: sample.footprint.clone(),
            average_steps: e.average_steps,
            phi_stop: e.phi_stop,
            pressure_stop: e.pressure_stop_pa,
            max_steps: e.max_steps,
            profile_every: e.profile_every_rows,
            rows: 0,
        })
    }

    /// Cross-section for φ and P: the box base (omni) or the projected area (uni), from the
    /// row measures `m` (which hold it where it was requested).
    fn area_of(&self, m: &RowMeasures) -> f64 {
        match self.kind {
            ExperimentKind::Omni => self.footprint.area(),
            _ => m.projected_area.expect("requested for every uni row"),
        }
    }

    /// What every row asks the engine for: the projected area for a uni run (the box base of
    /// an omni run is known), and the slabs of a profile where one is due.
    fn request(&self, slabs: Option<Slabs>) -> RowRequest {
        RowRequest {
            slabs,
            projected_area: self.kind != ExperimentKind::Omni,
        }
    }

    /// Cross-section for φ and P now: the box base (omni) or the projected area (uni).
    pub fn area(&mut self) -> Result<f64, EngineError> {
        let m = self.engine.row_measures(&self.request(None))?;
        Ok(self.area_of(&m))
    }

    pub fn wall_gap(&self) -> f64 {
        let w = self.engine.walls();
        (w[TOP_WALL].point - w[0].point).dot(w[0].normal)
    }

    fn measure(&mut self, p_top: f64, p_bottom: f64) -> Result<Row, EngineError> {
        let m = self.engine.row_measures(&self.request(None))?;
        let e = &self.engine;
        let area = self.area_of(&m);
        let gap = self.wall_gap();
        let v_mono = 4.0 / 3.0 * std::f64::consts::PI * e.law().radius.powi(3);
        let (contacts, wall_contacts) = m.contacts;
        // dyn/cm² → Pa
        Ok(Row {
            step: e.step_count(),
            time: e.time(),
            wall_gap: gap,
            area,
            phi: filling_factor(e.monomer_count(), v_mono, area, gap),
            p_top: 0.1 * p_top / area,
            p_bottom: 0.1 * p_bottom / area,
            contacts,
            wall_contacts,
            energy: m.energy,
        })
    }

    /// Filling factor in slabs one diameter thick between the bottom and the top wall, over
    /// the cross-section `area` of the row it belongs to.
    pub fn profile(&mut self, area: f64) -> Result<Vec<(f64, f64)>, EngineError> {
        let r = self.engine.law().radius;
        let w = self.engine.walls();
        let slabs = Slabs::between(w[0].point.z, w[TOP_WALL].point.z, 2.0 * r);
        let request = RowRequest {
            slabs: Some(slabs),
            projected_area: false,
        };
        let m = self.engine.row_measures(&request)?;
        Ok(slabs.profile(&m.slab_volumes, area))
    }

    /// Runs until a stop rule fires, reporting rows (and profiles) through `report`.
    pub fn run(
        &mut self,
        report: &mut dyn FnMut(Event<E>) -> Result<(), RunError>,
    ) -> Result<StopReason, RunError> {
        if self.engine.step_count() == 0 {
            let first = self.measure(f64::NAN, f64::NAN)?;
            report(Event::Row(&first))?;
            let profile = self.profile(first.area)?;
            report(Event::Profile(&first, &profile))?;
        }
        loop {
            let mean = self.engine.run_mean_wall_force(self.average_steps)?;
            let w = self.engine.walls();
            let top = mean[TOP_WALL].dot(w[TOP_WALL].normal);
            let bottom = mean[0].dot(w[0].normal);
            let row = self.measure(top, bottom)?;
            self.rows += 1;
            report(Event::Row(&row))?;
            let stop = if row.phi >= self.phi_stop {
                Some(StopReason::FillingFactor)
            } else if row.p_top >= self.pressure_stop {
                Some(StopReason::Pressure)
            } else if self.engine.step_count() >= self.max_steps {
                Some(StopReason::MaxSteps)
            } else {
                None
            };
            if stop.is_some()
                || (self.profile_every > 0 && self.rows.is_multiple_of(self.profile_every))
            {
                let profile = self.profile(row.area)?;
                report(Event::Profile(&row, &profile))?;
            }
            if let Some(reason) = stop {
                return Ok(reason);
            }
            report(Event::RowDone(self))?;
        }
    }
}
