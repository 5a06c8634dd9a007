"""Passive IQ recordings: SigMF and raw cf32/ci16 reading, writing, and one-line errors for bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

from cli_helpers import assert_one_line_error, skyradar
from skyradar.errors import InputError
from skyradar.io.sigmf_io import SigmfWriter, read_iq_recording, write_raw_iq

RX = {"latitude": 52.1, "longitude": 5.3, "altitude": 45.0}
TX = {"latitude": 52.063, "longitude": 5.1356, "altitude": 25.0, "carrier_frequency_hz": 2.8e9}


def _recording(tmp_path, n=4096, name="rec"):
    rng = np.random.default_rng(1)
    x = (rng.standard_normal(n) + 1j * rng.standard_normal(n)).astype(np.complex64)
    with SigmfWriter(tmp_path / f"{name}.sigmf-meta", 5e6, 2.8e9, RX, TX, {"noise_figure_db": 5.0}) as w:
        for block in np.array_split(x, 3):
            w.write(block)
    return tmp_path / f"{name}.sigmf-meta", x


def _edit_meta(meta, change):
    doc = json.loads(meta.read_text())
    change(doc)
    meta.write_text(json.dumps(doc))


def test_round_trip_and_chunks(tmp_path):
    meta, x = _recording(tmp_path)
    for name in ("rec.sigmf-meta", "rec.sigmf-data", "rec"):
        rec = read_iq_recording(tmp_path / name)
        np.testing.assert_array_equal(rec.read(0, rec.n_samples), x)
    starts = [s for s, _ in rec.chunks(1000, overlap=10)]
    assert starts == [0, 1000, 2000, 3000, 4000]
    np.testing.assert_array_equal(dict(rec.chunks(1000, overlap=10))[1000], x[1000:2010])
    assert rec.receiver == {"noise_figure_db": 5.0} and rec.illuminator["carrier_frequency_hz"] == 2.8e9
    assert rec.start_time.endswith("Z") and rec.center_frequency_hz == 2.8e9


def test_failed_write_leaves_nothing(tmp_path):
    with pytest.raises(RuntimeError), SigmfWriter(tmp_path / "r.sigmf-meta", 5e6, 2.8e9, RX, TX) as w:
        w.write(np.ones(10))
        raise RuntimeError("interrupted")
    assert list(tmp_path.iterdir()) == []


def test_raw_cf32_and_ci16_with_sidecar(tmp_path):
    x = (np.arange(64) / 128.0 * (1 - 0.5j)).astype(np.complex64)
    side = {"sample_rate_hz": 5e6, "center_frequency_hz": 2.8e9, "receiver": RX, "illuminator": TX}
    for datatype, suffix, tol in (("cf32_le", ".cf32", 0.0), ("ci16_le", ".ci16", 1 / 32768)):
        rec = read_iq_recording(write_raw_iq(tmp_path / f"r{suffix}", x, side, datatype))
        np.testing.assert_allclose(rec.read(0, 64), x, atol=tol)
        assert rec.illuminator_geodetic == (TX["latitude"], TX["longitude"], TX["altitude"])
    import yaml

    (tmp_path / "r.json").rename(tmp_path / "r.yaml")  # the ci16 file's sidecar, now as YAML
    (tmp_path / "r.yaml").write_text(yaml.safe_dump(json.loads((tmp_path / "r.yaml").read_text())))
    np.testing.assert_allclose(read_iq_recording(tmp_path / "r.ci16").read(0, 64), x, atol=1 / 32768)


@pytest.mark.parametrize(
    ("change", "needle"),
    [
        (lambda d: d["global"].update({"core:datatype": "cu8"}), "core:datatype"),
        (lambda d: d["global"]["skyradar:illuminator"].pop("latitude"), "no position"),
        (lambda d: d["global"].pop("skyradar:illuminator"), "no position"),
        (lambda d: d["global"].pop("core:geolocation"), "core:geolocation"),
        (lambda d: d["global"].update({"core:sample_rate": "fast"}), "not valid SigMF"),
        (lambda d: d["global"].update({"skyradar:sample_count": "many"}), "skyradar:sample_count"),
        (lambda d: d["global"].update({"skyradar:receiver": "x"}), "skyradar:receiver"),
        (
            lambda d: [
                d["captures"][0].pop("core:frequency"),
                d["global"]["skyradar:illuminator"].pop("carrier_frequency_hz"),
            ],
            "core:freq",
        ),
    ],
)
def test_bad_metadata_is_one_line(tmp_path, change, needle):
    meta, _ = _recording(tmp_path)
    _edit_meta(meta, change)
    with pytest.raises(InputError, match=needle) as err:
        read_iq_recording(meta)
    assert "\n" not in str(err.value) and str(meta) in str(err.value)


def test_truncated_data_is_one_line(tmp_path):
    meta, _ = _recording(tmp_path)
    data = tmp_path / "rec.sigmf-data"
    full = data.read_bytes()
    data.write_bytes(full[: 8 * 1000])
    with pytest.raises(InputError, match="shorter than the 4096"):
        read_iq_recording(meta)
    data.write_bytes(full[:8001])
    with pytest.raises(InputError, match="ends inside a sample"):
        read_iq_recording(meta)


def test_cf32_data_declared_ci16_is_one_line(tmp_path):
    # Float32 samples read as int16 pairs are bit patterns, not a signal: named as such, not as
    # "no direct-path pulse" after the whole recording is processed.
    meta, x = _recording(tmp_path)
    _edit_meta(meta, lambda d: d["global"].update({"core:datatype": "ci16_le"}))
    result = skyradar("passive", meta.name, "-o", "det.parquet", cwd=tmp_path)
    needles = ["rec.sigmf-data", "does not look like the declared datatype 'ci16_le'", "'core:datatype'"]
    assert_one_line_error(result, *needles, "rec.sigmf-meta")
    assert not (tmp_path / "det.parquet").exists()
    side = {"sample_rate_hz": 5e6, "center_frequency_hz": 2.8e9, "receiver": RX, "illuminator": TX}
    write_raw_iq(tmp_path / "raw.cf32", x, side).rename(tmp_path / "raw.ci16")  # sidecar raw.json kept
    result = skyradar("passive", "raw.ci16", "-o", "det.parquet", cwd=tmp_path)
    assert_one_line_error(result, "raw.ci16", "does not look like the declared datatype 'ci16_le'", "'.ci16'")


@pytest.mark.parametrize("level", [3e-4, 0.01, 0.25, 0.6])
def test_ci16_data_of_any_level_reads(tmp_path, level):
    # Noise from a few codes to clipping, and the tone with the most float32-like codes (0.65 of full
    # scale: 70 % of its samples): never taken for float32 data.
    rng = np.random.default_rng(2)
    n = 1 << 15
    noise = level * (rng.standard_normal(n) + 1j * rng.standard_normal(n))
    tone = 0.65 * np.exp(2j * np.pi * 0.0123 * np.arange(n))
    side = {"sample_rate_hz": 5e6, "center_frequency_hz": 2.8e9, "receiver": RX, "illuminator": TX}
    for name, x in (("noise", noise), ("tone", tone)):
        rec = read_iq_recording(write_raw_iq(tmp_path / f"{name}.ci16", x, side, "ci16_le"))
        assert rec.n_samples == n


def test_raw_without_sidecar_or_illuminator(tmp_path):
    (tmp_path / "x.cf32").write_bytes(np.zeros(8, np.complex64).tobytes())
    with pytest.raises(InputError, match="no sidecar"):
        read_iq_recording(tmp_path / "x.cf32")
    (tmp_path / "x.json").write_text(
        json.dumps({"sample_rate_hz": 5e6, "center_frequency_hz": 2.8e9, "receiver": RX})
    )
    with pytest.raises(InputError, match="no position"):
        read_iq_recording(tmp_path / "x.cf32")


def test_simulate_passive_cli_writes_a_readable_recording_and_refuses_bad_input(tmp_path):
    result = skyradar(
        "simulate-passive", "-o", "r.sigmf-meta", "--duration-s", "0.02", "--json", cwd=tmp_path
    )
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout.strip().splitlines()[-1])
    assert summary["samples"] == 100_000 and summary["aircraft"] == 1
    rec = read_iq_recording(tmp_path / "r.sigmf-meta")
    assert rec.n_samples == 100_000 and rec.truth_table_path is not None
    # Refusals before any work: an existing output and a sample rate below the pulses' band.
    again = skyradar("simulate-passive", "-o", "r.sigmf-meta", "--sample-rate-hz", "3e6", cwd=tmp_path)
    assert_one_line_error(again, "--overwrite")
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "r.sigmf-data",
        "r.sigmf-meta",
        "r.truth.json",
        "r.truth.parquet",
    ]


def test_passive_refuses_unreadable_recordings_in_one_line(tmp_path):
    """Bad inputs that belong to reading, through the real `skyradar passive` entry point."""
    cases = {
        "cu8": lambda d: d["global"].update({"core:datatype": "cu8"}),
        "short": None,
        "noillum": lambda d: d["global"]["skyradar:illuminator"].pop("latitude"),
    }
    for name, change in cases.items():
        meta, _ = _recording(tmp_path, name=name)
        if change is None:
            data = tmp_path / f"{name}.sigmf-data"
            data.write_bytes(data.read_bytes()[:8000])
        else:
            _edit_meta(meta, change)
    needles = {"cu8": ("core:datatype", "cu8"), "short": ("shorter than",), "noillum": ("no position",)}
    for name, words in needles.items():
        result = skyradar("passive", f"{name}.sigmf-meta", "-o", f"{name}.parquet", cwd=tmp_path)
        assert_one_line_error(result, f"{name}.sigmf", *words)
        assert not (tmp_path / f"{name}.parquet").exists()
