//! The dissipation tally: where the mechanical energy that left the monomers went, per channel.

/// Energy removed from the monomers' mechanical energy, per channel [erg].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dissipation {
    /// Potential left in monomer–monomer contacts when they break.
    pub breaking: f64,
    /// Minus the potential a contact has when it is found (formed slightly past δ = 0).
    pub forming: f64,
    /// Normal damping, monomer–monomer and monomer–wall.
    pub damping: f64,
    pub rolling: f64,
    pub sliding: f64,
    pub twisting: f64,
    /// Inelastic rolling, sliding, twisting, forming and breaking of wall contacts.
    pub walls: f64,
}

impl Dissipation {
    /// The channels in a fixed order (checkpoints, the GPU tally): breaking, forming, damping,
    /// rolling, sliding, twisting, walls.
    pub fn channels(&self) -> [f64; 7] {
        [
            self.breaking,
            self.forming,
            self.damping,
            self.rolling,
            self.sliding,
            self.twisting,
            self.walls,
        ]
    }

    /// The inverse of [`Dissipation::channels`].
    pub fn from_channels(c: [f64; 7]) -> Self {
        let [breaking, forming, damping, rolling, sliding, twisting, walls] = c;
        Dissipation {
            breaking,
            forming,
            damping,
            rolling,
            sliding,
            twisting,
            walls,
        }
    }

    /// The tally with the channels of the inelastic corrections (rolling, sliding, twisting,
    /// walls) marked not booked: NaN, which stays NaN whatever is added. An engine skips the
    /// step energies that only such channels would take (`[output] tally_corrections`).
    pub fn without_corrections(self) -> Dissipation {
        Dissipation {
            rolling: f64::NAN,
            sliding: f64::NAN,
            twisting: f64::NAN,
            walls: f64::NAN,
            ..self
        }
    }

    /// Whether any pair correction channel (rolling, sliding, twisting) is booked.
    pub fn books_pair_corrections(&self) -> bool {
        !(self.rolling.is_nan() && self.sliding.is_nan() && self.twisting.is_nan())
    }

    /// Whether the wall channel is booked.
    pub fn books_wall_corrections(&self) -> bool {
        !self.walls.is_nan()
    }

    /// Adds another tally channel by channel.
    pub fn add(&mut self, other: &Dissipation) {
        self.breaking += other.breaking;
        self.forming += other.forming;
        self.damping += other.damping;
        self.rolling += other.rolling;
        self.sliding += other.sliding;
        self.twisting += other.twisting;
        self.walls += other.walls;
    }

    pub fn total(&self) -> f64 {
        self.breaking
            + self.forming
            + self.damping
            + self.rolling
            + self.sliding
            + self.twisting
            + self.walls
    }
}
