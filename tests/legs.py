"""Where each test runs in CI: the one list (issue 45).

CI runs three QGIS legs (``.ci/run``): the host (Debian 12: QGIS 3.22, Python 3.11, NumPy 1.24) runs EVERY test
(``make test``, the README's command); the two chroot legs (QGIS 3.40 / Python 3.13 / NumPy 2.2 and QGIS 3.44 /
Python 3.14 / NumPy 2.x) run the tests marked ``every_leg`` (``PYTEST_ARGS=-m every_leg``).

The rule, by what a test exercises:

- every test file is listed in ``FILES`` with what of the platform it exercises (``qgis``: QGIS/Qt API, the
  plugin, Processing, widgets; ``qgis_process``: headless runs as a user makes them; ``gdal``: GDAL/OGR/PROJ
  reading and writing; ``install``: the installer, packaging, imports; ``core``: numerical code on NumPy, SciPy,
  OpenCV and pycolmap only);
- every test runs on every leg (marker ``every_leg``), except those named in ``ONE_LEG``: end-to-end runs whose cost
  is the numerical work of core/ (rendering a synthetic block, aligning it, matching it densely) and whose platform
  dependence -- the NumPy 2 paths, Python 3.13/3.14, GDAL/PROJ, QGIS -- is already exercised on every leg by the
  cheaper tests of the same code (each entry says which);
- nothing that exercises the platform above ``core`` is one-leg in the files of ``PLATFORM_ONLY_EVERY_LEG``: the
  installer, the imports, the Qt6/QGIS API checks, QGIS desktop, the Processing dialogs and the package.

``tests/test_legs.py`` keeps this complete: every test file is in ``FILES`` (and nothing else is), every
``ONE_LEG`` entry names an existing test, and the platform files have no one-leg test.
"""

FILES = {
    "test_accuracy.py": "core",
    "test_align.py": "core",
    "test_align_blocks.py": "core",
    "test_align_degenerate.py": "core",
    "test_align_escalation.py": "core",
    "test_align_focal_drift.py": "core",
    "test_align_relaxed.py": "core",
    "test_align_texture.py": "core",
    "test_architecture.py": "install",
    "test_archive_scene.py": "gdal",
    "test_autocontrol.py": "qgis_process",
    "test_autocontrol_faces.py": "qgis",
    "test_autocontrol_national.py": "gdal",
    "test_autocontrol_orbit.py": "core",
    "test_bad_inputs_more.py": "gdal",
    "test_band_radiometry.py": "core",
    "test_band_registration.py": "gdal",
    "test_bundle_solver.py": "core",
    "test_calibrated_cameras.py": "qgis",
    "test_calibration_files.py": "core",
    "test_captures.py": "qgis_process",
    "test_control_sigma.py": "core",
    "test_coregister.py": "gdal",
    "test_dask.py": "core",
    "test_dem_control.py": "qgis",
    "test_dense.py": "qgis_process",
    "test_dense_fill.py": "gdal",
    "test_dense_lowtexture.py": "core",
    "test_dense_walls.py": "core",
    "test_dependencies.py": "install",
    "test_epochs.py": "qgis_process",
    "test_face_errors.py": "qgis",
    "test_find_targets.py": "qgis",
    "test_frame.py": "core",
    "test_gcp.py": "gdal",
    "test_gcp_block.py": "core",
    "test_georef.py": "core",
    "test_georef_stage.py": "gdal",
    "test_georef_synthetic.py": "core",
    "test_images.py": "gdal",
    "test_imports.py": "install",
    "test_legs.py": "install",
    "test_masks.py": "qgis",
    "test_multispectral.py": "gdal",
    "test_obliques.py": "qgis",
    "test_orientation.py": "qgis",
    "test_ortho.py": "qgis",
    "test_overwrite_inputs.py": "qgis_process",
    "test_package.py": "install",
    "test_panel_calibration.py": "qgis_process",
    "test_pipeline.py": "qgis_process",
    "test_pipeline_panel.py": "qgis_process",
    "test_point_in_polygon.py": "core",
    "test_primary_band.py": "gdal",
    "test_processing_help.py": "qgis",
    "test_projection.py": "core",
    "test_qgis_desktop.py": "qgis",
    "test_qgis_plugin.py": "qgis",
    "test_qt6_ready.py": "install",
    "test_radiometry.py": "gdal",
    "test_ransac_bound.py": "core",
    "test_rasterfile.py": "gdal",
    "test_reliability_inputs.py": "gdal",
    "test_reliability_photos.py": "core",
    "test_reliability_runs.py": "qgis_process",
    "test_report.py": "qgis",
    "test_resection.py": "core",
    "test_rig_block.py": "core",
    "test_rig_calibration.py": "gdal",
    "test_rig_rgb.py": "core",
    "test_scans.py": "qgis",
    "test_screening.py": "qgis_process",
    "test_seamlines.py": "qgis_process",
    "test_single_autocontrol.py": "qgis_process",
    "test_spectral_index.py": "qgis_process",
    "test_terrain.py": "qgis_process",
    "test_terrain_tiles.py": "gdal",
    "test_terrain_units.py": "gdal",
    "test_ui_dock.py": "qgis",
    "test_ui_dock_edits.py": "qgis",
    "test_ui_dock_layout.py": "qgis",
    "test_ui_find_targets.py": "qgis",
    "test_ui_guided.py": "core",
    "test_ui_i18n.py": "qgis",
    "test_ui_layers.py": "qgis",
    "test_ui_report_output.py": "qgis",
    "test_ui_walkthrough.py": "qgis",
    "test_woodland_block.py": "core",
    "test_workspace.py": "core",
    "test_workspace_concurrency.py": "core",
}

ASPECTS = ("qgis", "qgis_process", "gdal", "install", "core")

# Files whose every test runs on every leg, whatever it costs: what they check IS the platform.
PLATFORM_ONLY_EVERY_LEG = (
    "test_dependencies.py", "test_imports.py", "test_legs.py", "test_package.py", "test_qt6_ready.py",
    "test_qgis_desktop.py", "test_qgis_plugin.py", "test_processing_help.py", "test_ui_i18n.py",
)

# a file (all its tests) or file::test (all its parametrisations) -> why once is enough
ONE_LEG = {
}


def one_leg(nodeid):
    """True when the test of ``nodeid`` (``tests/test_x.py::test_y[param]`` or ``test_x.py::Class::test_y``) runs
    on the host leg only."""
    path, _, rest = nodeid.partition("::")
    key = path.rsplit("/", 1)[-1] + "::" + rest.split("[", 1)[0]
    return key in ONE_LEG or path.rsplit("/", 1)[-1] in ONE_LEG
