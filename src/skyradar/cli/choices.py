"""The fixed choices of the command-line options, one string enum each.

An option typed with one of these enums lists its choices in ``--help`` and in the CLI reference,
and a value outside them is refused before the command runs: one line on stderr naming the option,
its choices and the value, exit code 2 (:func:`skyradar.cli.main`). The commands pass ``.value`` on,
so the library functions keep taking plain strings.

Where the library holds the same names (``FAMILIES``, ``COMPRESSORS``, ...) the enum repeats them
rather than importing the library module, which would make every ``skyradar`` command start slower;
``tests/test_cli_choices.py`` checks that the two agree. Options whose value may also be a path or a
list (``--terrain``, ``alert --config``, window specs) stay strings checked by hand.
"""

from __future__ import annotations

from enum import StrEnum

__all__ = [
    "Detector",
    "SpurMode",
    "Suppression",
    "SpurPixels",
    "Ch3Path",
    "TrackerModel",
    "TruthMode",
    "Ch4Chain",
    "StateMethod",
    "AircraftClass",
    "Side",
    "Compressor",
    "Precision",
    "GpsCheckMethod",
    "PassivePulse",
    "PassiveScenario",
    "Layout",
    "ClosedLoopFamily",
    "Manoeuvre",
    "Navigation",
    "RxLayout",
    "Family",
    "Split",
    "EncounterTerrain",
]


class Detector(StrEnum):
    """``process --method``: the detector."""

    cfar = "cfar"
    os_cfar = "os-cfar"
    shi_tomasi = "shi-tomasi"


class SpurMode(StrEnum):
    """``process --spur-mode``: mask spur pixels before detection, or flag detections in them."""

    mask = "mask"
    flag = "flag"


class Suppression(StrEnum):
    """``process --suppression``: ground clutter suppression before detection."""

    auto = "auto"
    knowledge_aided = "knowledge-aided"
    none = "none"


class SpurPixels(StrEnum):
    """``spur-map --pixels``: the detector's points, or every lit pixel."""

    peaks = "peaks"
    hits = "hits"


class Ch3Path(StrEnum):
    """``experiment ch3 --path``: the flyover path."""

    circuit = "circuit"
    approach = "approach"


class TrackerModel(StrEnum):
    """``track --model``: the aliasing-aware radar tracker or the traditional image tracker."""

    radar = "radar"
    traditional = "traditional"


class TruthMode(StrEnum):
    """``evaluate --truth``: which truth rows count (``skyradar.track.evaluate.TRUTH_MODES``)."""

    detectable = "detectable"
    beam = "beam"


class Ch4Chain(StrEnum):
    """``experiment ch4 --chain``: the whole chain, or detections made from the truth."""

    full = "full"
    geometry = "geometry"


class StateMethod(StrEnum):
    """``state --method``: the flight-state estimator."""

    robust = "robust"
    thesis = "thesis"
    terrain = "terrain"


class AircraftClass(StrEnum):
    """``flight --aircraft-class``, ``make-encounter --ownship-class/--intruder-class``: whose
    kinematic limits a built path keeps to."""

    ga = "ga"
    glider = "glider"
    transport = "transport"
    any = "any"


class Side(StrEnum):
    """``make-encounter --side``: the side of the own ship's track the intruder passes."""

    right = "right"
    left = "left"


class Compressor(StrEnum):
    """``simulate/rd --compress``: the pixels' lossless codec (``skyradar.io.frames.COMPRESSORS``)."""

    none = "none"
    zstd = "zstd"
    blosc = "blosc"


class Precision(StrEnum):
    """``simulate/rd --precision``: the pixel format (``skyradar.io.frames.PRECISIONS``)."""

    complex64 = "complex64"
    cint16 = "cint16"


class GpsCheckMethod(StrEnum):
    """``gpscheck --method``: the pre-processing (``skyradar.nav.gpscheck.preprocess.METHODS``)."""

    gamma = "gamma"
    threshold_entropy = "threshold_entropy"
    clahe_ridge = "clahe_ridge"
    clahe_entropy = "clahe_entropy"


class PassivePulse(StrEnum):
    """``passive --pulse``: the matched filter's template."""

    metadata = "metadata"
    recording = "recording"


class PassiveScenario(StrEnum):
    """``simulate-passive SCENARIO``: the built-in geometry."""

    thesis = "thesis"


class Layout(StrEnum):
    """``experiment encounters --layout``: the radar heads scored."""

    both = "both"
    single = "single"
    three_head = "three-head"


class Navigation(StrEnum):
    """``experiment encounters --navigation``: the own-ship navigation error model
    (``skyradar.scene.navigation_config.NAVIGATION_MODELS``)."""

    perfect = "perfect"
    ga_typical = "ga-typical"
    only_gnss_position = "only-gnss-position"
    only_gnss_velocity = "only-gnss-velocity"
    only_attitude = "only-attitude"
    only_heading = "only-heading"
    only_latency = "only-latency"


class RxLayout(StrEnum):
    """``experiment encounters --rx-layout``: every head's array (``skyradar.rx_layouts.RX_LAYOUTS``,
    then ``MIMO_LAYOUTS``)."""

    square = "square"
    kite = "kite"
    ura_2x3 = "ura-2x3"
    ura_2x4 = "ura-2x4"
    ura_4x2 = "ura-4x2"
    mimo_2x4 = "mimo-2x4"


class Family(StrEnum):
    """``experiment encounters --family``: the encounter set
    (``skyradar.experiments.encounters.FAMILIES``)."""

    synthetic = "synthetic"
    real_flights = "real-flights"
    fast_closures = "fast-closures"


class ClosedLoopFamily(StrEnum):
    """``experiment closed-loop --family``: the encounter set flown closed-loop
    (``skyradar.experiments.closed_loop.CLOSED_LOOP_FAMILIES``)."""

    synthetic = "synthetic"
    fast_closures = "fast-closures"


class Manoeuvre(StrEnum):
    """``experiment closed-loop --manoeuvre``: the advice the pilot flies (``skyradar.pilot.PilotConfig``)."""

    horizontal = "horizontal"
    vertical = "vertical"


class Split(StrEnum):
    """``experiment encounters --split``: the seeds to tune on, or to report on."""

    development = "development"
    evaluation = "evaluation"


class EncounterTerrain(StrEnum):
    """``bench encounter --terrain``: one encounter terrain
    (``skyradar.experiments.encounter_terrain.TERRAINS``)."""

    none = "none"
    flat_300 = "flat-300"
    flat_1000 = "flat-1000"
    hills = "hills"
    jacksboro = "jacksboro"
