"""Reading and writing frames (xarray/Zarr) and tables (Parquet), recordings, and the output guard.

The names users call, importable from here (each is imported from its module on first use, so
``import skyradar.io`` stays cheap):

- :func:`~.frames.open_frames`, :func:`~.frames.frames_dataset` and :func:`~.frames.radar_config_of`:
  frames stores;
- :func:`~.tables.read_table` and :func:`~.tables.write_table`: Parquet (or CSV) tables;
- :func:`~.recordings.read_recording`, :func:`~.recording_writer.write_recording` and
  :func:`~.recording_writer.write_sigmf_recording`: raw ADC recordings (a sidecar beside the
  samples, or SigMF); :func:`~.sigmf_io.read_iq_recording`: a passive receiver's IQ;
- :func:`~.outputs.check_output`: the check every writing command makes before any work;
- :class:`~.ownship_states.OwnShipStates`: the own-ship's navigated state per frame, the typed
  object process, clutter suppression and alerting take.

Modules: frames (:mod:`.frames`, :mod:`.frames_model`, :mod:`.frames_heads`, :mod:`.cint16`,
:mod:`.checks`, :mod:`.store_size`, :mod:`.navigation`, :mod:`.ownship_states`, :mod:`.run_origin`,
:mod:`.run_export`, :mod:`.ownship_input`); tables (:mod:`.tables`, :mod:`.table_columns`); JSON
results (:mod:`.json_results`); recordings (:mod:`.recordings`, :mod:`.recording_sigmf`,
:mod:`.recording_writer`, :mod:`.sigmf_io`, :mod:`.iq_raw`, :mod:`.iq_recording`); writing safely
(:mod:`.outputs`, :mod:`.atomic`, :mod:`.locks`) and reading safely (:mod:`.safe_yaml`).
"""

from __future__ import annotations

from skyradar.lazy_exports import lazy_exports

# Each public name by the module it lives in, imported on first use (PEP 562).
_EXPORTS = {
    "frames": ("open_frames", "frames_dataset", "radar_config_of"),
    "tables": ("read_table", "write_table"),
    "recordings": ("read_recording",),
    "recording_writer": ("write_recording", "write_sigmf_recording"),
    "sigmf_io": ("read_iq_recording",),
    "outputs": ("check_output",),
    "ownship_states": ("OwnShipStates",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
