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
