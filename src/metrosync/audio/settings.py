"""The audio analysis's settings, in a module that imports nothing heavy, so that
building the ``metrosync`` parser stays quick: the detector's defaults that the command
line shows, and the timing model's parameters (`TimingModel`, `MODEL`)."""

from dataclasses import dataclass, field, fields

#: Band-pass edges of the tick detector, Hz, when none is given; at a sample rate too
#: low for its top, the top is lowered to `DEFAULT_TOP` × the sample rate.
DEFAULT_BAND = (1000.0, 10000.0)
DEFAULT_TOP = 0.45
#: Threshold above the detection curve's median, in its robust spreads.
DEFAULT_SENSITIVITY = 4.5
#: Largest phase gap inside one cluster of ticks, fraction of a beat.
CLUSTER_GAP = 1 / 16


@dataclass(frozen=True)
class TimingModel:
    """The parameters of the timing model (docs/sound.md, "How it works"): what a
    metronome and a tick may be, and how sure each of the model's decisions must be.
    Each field's unit and meaning are its metadata (`TimingModel.described`). The
    numerical settings of the fits (iterations, grids, floors, fewest samples) stay
    with the modules that run them; they change how a fit converges, not the model."""

    bpm_range: tuple[float, float] = field(default=(30.0, 300.0), metadata={
        "unit": "BPM", "meaning": "tempi a metronome may keep (every mechanical "
        "metronome's marks lie inside)"})
    harmonics: int = field(default=4, metadata={
        "unit": "", "meaning": "harmonics of each trial tempo summed by the periodicity "
        "search (Z²_m): up to this many metronomes of one tempo splayed evenly over the "
        "beat are still a candidate"})
    false_alarm: float = field(default=1e-3, metadata={
        "unit": "probability", "meaning": "false-alarm probability of the model's tests: "
        "a candidate tempo in a recording with no period, an impact of a tick taken for "
        "another metronome's beat passing or locked to it"})
    jitter_dof: float = field(default=4.0, metadata={
        "unit": "", "meaning": "degrees of freedom of the Student-t law of a tick's "
        "timing error (few: a tick several jitters off weighs little)"})
    heard_share: float = field(default=0.5, metadata={
        "unit": "share of beats", "meaning": "a metronome's strike, the impact that "
        "times its tick, is heard in at least this share of its beats"})
    min_beats: int = field(default=16, metadata={
        "unit": "beats", "meaning": "fewest beats a metronome spans, and the first "
        "stretch it is followed on (eight of each kind)"})
    strike_spread: float = field(default=2.5, metadata={
        "unit": "ratio", "meaning": "an impact whose timing spreads more than this many "
        "times the most regular one's is not the strike (a precursor's lead wanders by "
        "milliseconds); of those within it (the strike and the bounces it makes, which "
        "keep its jitter), the loudest is the strike"})
    impact_spread: tuple[float, float] = field(default=(0.2e-3, 15e-3), metadata={
        "unit": "s", "meaning": "narrowest spread of an impact about its tick (the onset "
        "detector's timing noise) and widest (a precursor's wandering lead keeps to its "
        "tick; wider is another metronome's beat sliding past)"})
    reach: float = field(default=0.45, metadata={
        "unit": "beat", "meaning": "how far a tick's impacts reach from its beat; "
        "onsets farther off are another beat's or clutter"})
    sound_apart: float = field(default=1000.0, metadata={
        "unit": "likelihood ratio", "meaning": "an onset is another metronome's by its "
        "sound where that one's likelihood is this many times this one's"})
    place_db: float = field(default=3.0, metadata={
        "unit": "dB", "meaning": "difference of level between microphones beyond which "
        "two impacts come from two places"})
    seek_false_tick: float = field(default=0.01, metadata={
        "unit": "share of windows", "meaning": "share of a beat's windows with no tick "
        "in which the search for an unheard beat finds one by chance"})
    seek_window: tuple[float, float] = field(default=(3.0, 1e-3), metadata={
        "unit": "jitters, s", "meaning": "half-width of the window an unheard beat is "
        "sought in: this many of its metronome's jitters, and at least this long; an "
        "onset further than the second off its strike's prediction has the strike "
        "sought by its sound too"})
    sound_length: float = field(default=0.012, metadata={
        "unit": "s", "meaning": "length of a metronome's sound matched where a beat is "
        "sought by it: a strike's first milliseconds, before its ring"})
    ring: float = field(default=0.045, metadata={
        "unit": "s", "meaning": "how long a tick rings over the beats after it (where "
        "the chance level of the sound's match is read, and what a clean tick is clear "
        "of)"})

    @classmethod
    def described(cls) -> list[tuple[str, object, str, str]]:
        """(name, default, unit, meaning) of each parameter, in order."""
        return [(f.name, f.default, f.metadata["unit"], f.metadata["meaning"])
                for f in fields(cls)]  # fmt: skip


#: The timing model's parameters as the analysis uses them.
MODEL = TimingModel()
