"""The run folder: its schema (file names, array names, units), writing and reading it.

This package is the one place that knows what a run folder holds. The runner writes through it
(:func:`write_trajectory`, :func:`write_summary`, :func:`write_csv`, :func:`write_text`),
and sizing, plots, video and ``cellsim render`` read through it: in the runner from the
in-memory :class:`RunRecord`, afterwards with :func:`load_run`.

A run folder DIR holds (``FILES`` lists them):

* ``model.xml``: the compiled cell (``mujoco.MjModel.from_xml_path``);
* ``scenario.toml``: the scenario as given; ``manifest.json``: versions and hashes;
* ``summary.json``: ``scenario``, ``robot``, ``joints`` (names), ``phases``
  (``[{"name", "kind", "t0", "t1"}]``), ``duration_s``, metrics, ``saturation``, ``sizing``, ``checks``, ``verdict``, ...;
* ``trajectory.npz``: the recorded arrays (``ARRAYS`` gives each one's shape and unit);
  ``trajectory.csv``: the main ones as columns;
* ``video.mp4``, ``plots/*.png``, the sizing report (``sizing.md``, ``sizing.csv``,
  ``sizing.json``, ``report.html``, ``sizing/*.png``);
* with an actuator selection, ``selection.json`` and ``selection.csv``
  (:mod:`sim.analysis.selection`).

A run that fails mid-simulation keeps what it recorded in ``DIR.failed/`` with ``error.txt``.

The package, one concept per module (every name importable from ``sim.simulation.runfolder``):

* :mod:`~sim.simulation.runfolder.schema`: file and array names, shapes, units, reading bounds;
* :mod:`~sim.simulation.runfolder.record`: :class:`RunRecord` and :class:`Phase`, the run in
  memory;
* :mod:`~sim.simulation.runfolder.confine`: the confinement of ``model.xml``'s files to the
  folder, as MuJoCo 4.0 resolves them;
* :mod:`~sim.simulation.runfolder.reading`: :func:`load_run` and the bounded readers;
* :mod:`~sim.simulation.runfolder.writing`: the writers of the folder's files;
* :mod:`~sim.simulation.runfolder.place`: the marker, the lock, stale leftovers, ``--out``.

May import: :mod:`sim.core` and :mod:`sim.errors` only.
"""

from __future__ import annotations

from sim.errors import (
    RunFolderError,  # the error its readers raise (tests import it here)
)
from sim.simulation.runfolder.confine import (
    MAX_MODEL_ELEMENTS,
    _mj_reduce,
    confine_model_files,
    model_file_names,
)
from sim.simulation.runfolder.place import (
    INVENTORY,
    MAX_NAME_BYTES,
    RunLock,
    check_out_dir,
    failed_folder,
    foreign_entries,
    is_run_folder,
    make_folder,
    marker_state,
    note_written,
    remove_stale,
    write_marker,
    written_by_cellsim,
)
from sim.simulation.runfolder.reading import (
    _read_trajectory,
    as_record,
    load_run,
    read_run_json,
    read_run_summary,
    read_run_trajectory,
)
from sim.simulation.runfolder.record import (
    Phase,
    RunRecord,
)
from sim.simulation.runfolder.schema import (
    ARRAYS,
    ERROR_TXT,
    FAILED_SUFFIX,
    FILES,
    JOINT_ARRAYS,
    MANIFEST_JSON,
    MARKER,
    MAX_ASSET_BYTES,
    MAX_MODEL_BYTES,
    MAX_SUMMARY_BYTES,
    MAX_TRAJECTORY_ARRAYS,
    MAX_TRAJECTORY_BYTES,
    MODEL_XML,
    PLOTS_DIR,
    REPORT_HTML,
    REQUIRED_FOR_PLOTS,
    REQUIRED_FOR_VIDEO,
    SCENARIO_TOML,
    SELECTION_CSV,
    SELECTION_JSON,
    SIZING_CHARTS_DIR,
    SIZING_CSV,
    SIZING_JSON,
    SIZING_MD,
    SUMMARY_JSON,
    TRAJECTORY_CSV,
    TRAJECTORY_NPZ,
    VIDEO_MP4,
    ArraySpec,
    file_error,
    short_repr,
)
from sim.simulation.runfolder.writing import (
    CSV_JOINT_ARRAYS,
    decimate,
    sample_rate,
    write_csv,
    write_summary,
    write_text,
    write_trajectory,
)

__all__ = [
    "ARRAYS",
    "CSV_JOINT_ARRAYS",
    "ERROR_TXT",
    "FAILED_SUFFIX",
    "FILES",
    "JOINT_ARRAYS",
    "MANIFEST_JSON",
    "MARKER",
    "MAX_ASSET_BYTES",
    "MAX_MODEL_BYTES",
    "MAX_MODEL_ELEMENTS",
    "MAX_NAME_BYTES",
    "MAX_SUMMARY_BYTES",
    "MAX_TRAJECTORY_ARRAYS",
    "MAX_TRAJECTORY_BYTES",
    "MODEL_XML",
    "PLOTS_DIR",
    "REPORT_HTML",
    "REQUIRED_FOR_PLOTS",
    "REQUIRED_FOR_VIDEO",
    "SCENARIO_TOML",
    "SELECTION_CSV",
    "SELECTION_JSON",
    "SIZING_CHARTS_DIR",
    "SIZING_CSV",
    "SIZING_JSON",
    "INVENTORY",
    "SIZING_MD",
    "SUMMARY_JSON",
    "TRAJECTORY_CSV",
    "TRAJECTORY_NPZ",
    "VIDEO_MP4",
    "ArraySpec",
    "Phase",
    "RunFolderError",
    "RunLock",
    "RunRecord",
    "_mj_reduce",
    "_read_trajectory",
    "as_record",
    "check_out_dir",
    "confine_model_files",
    "decimate",
    "failed_folder",
    "file_error",
    "foreign_entries",
    "is_run_folder",
    "load_run",
    "make_folder",
    "marker_state",
    "model_file_names",
    "note_written",
    "read_run_json",
    "read_run_summary",
    "read_run_trajectory",
    "remove_stale",
    "sample_rate",
    "short_repr",
    "write_csv",
    "write_marker",
    "written_by_cellsim",
    "write_summary",
    "write_text",
    "write_trajectory",
]
