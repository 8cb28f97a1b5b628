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
    "test_align_faint.py": "core",
    "test_align_focal_drift.py": "core",
    "test_align_join.py": "core",
    "test_align_links.py": "core",
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
    "test_control_checks.py": "gdal",
    "test_control_sigma.py": "core",
    "test_coregister.py": "gdal",
    "test_dask.py": "core",
    "test_dem_control.py": "qgis",
    "test_dense.py": "qgis_process",
    "test_dense_fill.py": "gdal",
    "test_dense_lowtexture.py": "core",
    "test_dense_walls.py": "core",
    "test_dependencies.py": "install",
    "test_drone_shadow.py": "gdal",
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
    "test_model.py": "core",
    "test_model_tiles.py": "gdal",
    "test_multispectral.py": "gdal",
    "test_obliques.py": "qgis",
    "test_orientation.py": "qgis",
    "test_ortho.py": "qgis",
    "test_overwrite_inputs.py": "qgis_process",
    "test_package.py": "install",
    "test_panel_calibration.py": "qgis_process",
    "test_parallel_budget.py": "core",
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

# Why once is enough, by kind of work (the cheaper tests named run the same code on every leg):
_SFM = ("alignment end to end on a rendered or real block: the cost is COLMAP's mapping; pycolmap's wheel of each "
        "Python and the align stage's NumPy paths run on every leg in test_align.py (the sample strip), "
        "test_align_blocks.py, test_align_join.py and test_resection.py")
_DENSE = ("dense matching of a rendered block end to end: the stereo, fusion and DSM writing run on every leg in "
          "test_dense.py (the synthetic block, its COG and LAS, qgis_process) and test_dense_fill.py's units")
_MOSAIC = ("a mosaic of a rendered block judged against its truth: the mosaic, its radiometric fit and the COG writer "
           "run on every leg in test_ortho.py, test_seamlines.py and test_radiometry.py's units")
_GEOREF = ("georeferencing a block aligned end to end: the adjustment runs on every leg on exact models "
           "(test_georef.py, test_georef_synthetic.py's truth-model tests, test_bundle_solver.py)")
_AUTOCONTROL = ("automatic control on two rendered epochs: the matching against a reference runs on every leg in "
                "test_autocontrol_faces.py (the Processing and dock faces), test_autocontrol_national.py and "
                "test_single_autocontrol.py")
_RIG = ("a multispectral rig block through the whole chain: stacking, band registration and radiometry run on every "
        "leg in test_captures.py, test_band_registration.py, test_band_radiometry.py and test_primary_band.py")
_RASTER = ("numerical equality of a raster computed two ways at full size: the tiled code runs on every leg on the "
           "smaller rasters of the same file")

ONE_LEG = {
    "test_align.py::test_foreign_images_are_reported_not_registered": _SFM,
    "test_align.py::test_global_mapper_aligns_the_strip": _SFM,
    "test_align_escalation.py::test_fast_path_fails_on_small_low_contrast_frames_and_escalation_fixes_it": _SFM,
    "test_align_escalation.py::test_mixed_cameras_register_in_one_block": _SFM,
    "test_align_focal_drift.py::test_garfield_registers_every_photo_and_holds_its_shape": _SFM,
    "test_align_relaxed.py::test_the_second_pass_registers_the_steep_views_the_first_pass_left_out": _SFM,
    "test_align_texture.py::test_faint_periodic_texture_gets_a_richer_first_pass": _SFM,
    "test_align_texture.py::test_the_users_settings_are_not_probed": _SFM + " (shares the faint photos' rendering)",
    "test_align_texture.py::test_the_first_pass_registers_a_faint_block_without_escalation": _SFM,
    "test_align_texture.py::test_a_large_blocks_escalation_continues_the_block": _SFM,
    "test_woodland_block.py::test_every_photo_of_the_woodland_block_is_registered": _SFM,
    "test_woodland_block.py::test_camera_centres_and_reprojection_against_the_truth": _SFM,
    "test_calibrated_cameras.py::test_a_fixed_calibration_is_held_through_alignment_and_georeference": _SFM,
    "test_calibrated_cameras.py::test_a_wrong_start_value_moves_when_estimated": _SFM,
    "test_calibrated_cameras.py::test_align_images_with_a_calibration_for_one_strip_holds_that_camera":
        _SFM + "; Align images' calibration parameters are read on every leg by "
               "test_align_images_refuses_a_mistyped_interior_orientation_and_a_bad_file",
    "test_calibrated_cameras.py::test_four_archive_frames_keep_their_calibrated_focal_length_and_their_height": _SFM,
    "test_calibrated_cameras.py::test_film_scans_restituted_by_prepare_images_keep_their_interior_orientation": _SFM,
    "test_calibrated_cameras.py::test_the_automatic_control_keeps_a_fixed_camera": _AUTOCONTROL,
    "test_obliques.py::test_orbit_sky_masks_before_alignment": _SFM,
    "test_obliques.py::test_orbit_every_camera_registered_and_no_sky_tie_point": _SFM,
    "test_obliques.py::test_orbit_poses_within_the_nadir_tolerances": _SFM,
    "test_obliques.py::test_orbit_no_dense_point_from_the_sky": _SFM,
    "test_obliques.py::test_orbit_mosaic_ground_marks_within_one_and_a_half_gsd": _SFM,
    "test_georef_synthetic.py::test_end_to_end_five_control_points_reach_one_gsd": _GEOREF,
    "test_georef_synthetic.py::test_end_to_end_camera_positions_only": _GEOREF,
    "test_georef_synthetic.py::test_end_to_end_stage_names_and_ignores_an_observation_outside_the_image": _GEOREF,
    "test_autocontrol.py": _AUTOCONTROL,
    "test_autocontrol_orbit.py": _AUTOCONTROL,
    "test_dense_walls.py": _DENSE,
    "test_dense_fill.py::test_low_texture_ground_is_measured": _DENSE,
    "test_dense_fill.py::test_low_texture_block_keeps_building_edges_sharp": _DENSE,
    "test_dense_lowtexture.py::test_farmland_dsm_is_mostly_measured_and_near_the_truth_on_the_fields": _DENSE,
    "test_dense_lowtexture.py::test_farmland_blunders_are_removed_and_flagged": _DENSE,
    "test_radiometry.py::test_falloff_and_hot_spot_are_recovered": _MOSAIC,
    "test_radiometry.py::test_seam_step_within_two_percent": _MOSAIC,
    "test_radiometry.py::test_mosaic_against_the_true_albedo": _MOSAIC,
    "test_radiometry.py::test_a_soft_edge_of_light_across_each_photo_is_levelled": _MOSAIC,
    "test_archive_scene.py::test_projected_points_land_on_the_same_texture": (
        "the archive scene's rendering checked against its own truth (scene code, not the plugin's): the scene's "
        "reading and writing run on every leg in the file's other tests"),
    "test_terrain_tiles.py::test_relief_by_small_tiles_equals_the_whole_raster": _RASTER,
    "test_rig_block.py::test_the_rig_block_is_stacked_aligned_and_mosaicked_with_every_band": _RIG,
    "test_rig_block.py::test_bands_registered_and_reflectance_steady_in_the_mosaic": _RIG,
    "test_rig_block.py::test_the_crop_mark_shows_in_ndvi_as_in_the_truth": _RIG,
    "test_rig_rgb.py::test_the_rgb_frames_and_the_captures_align_as_one_block": _RIG,
    "test_rig_rgb.py::test_two_orthomosaics_on_one_dsm_where_the_truth_is": _RIG,
    "test_rig_calibration.py::test_the_block_calibration_recovers_the_true_rig_rotations": _RIG,
    "test_rig_calibration.py::test_a_capture_over_uniform_ground_takes_the_block_s_correction": _RIG,
    "test_rig_calibration.py::test_a_capture_disagreeing_with_the_block_takes_its_correction_and_is_named": _RIG,
    "test_band_registration.py::test_synthetic_rig_with_wrong_relatives_is_refined": _RIG,
    "test_panel_calibration.py::test_the_orthomosaic_of_reflectance_photos_is_reflectance": _RIG,
    "test_pipeline.py::test_runpipeline_from_qgis_process_and_resume": (
        "the whole chain through qgis_process and its resume: the chain's stages run on every leg in their own "
        "files; Run pipeline's parameters reach qgis_process on every leg in test_pipeline_panel.py's "
        "test_qgis_process_run_pipeline_refuses_a_bad_panel, the shipped model in "
        "test_shipped_model_chains_the_stages_through_the_workspace"),
    "test_rig_rgb.py::test_only_the_stacked_captures_rgb_frames_are_aligned": _RIG,
    "test_drone_shadow.py::test_no_cell_of_a_speck_comes_from_its_photo": _MOSAIC,
    "test_pipeline_panel.py::test_run_pipeline_with_the_panel_gives_a_reflectance_orthomosaic":
        _RIG + "; Run pipeline's panel parameters reach qgis_process on every leg in "
               "test_qgis_process_run_pipeline_refuses_a_bad_panel",
}


# The costliest files first (measured: CI's host leg, 7 Dec), so that pytest-xdist's two workers finish together
# instead of one running the last heavy file alone; the rest keep their order.
SLOWEST_FIRST = (
    "test_dense_walls.py", "test_rig_rgb.py", "test_woodland_block.py", "test_obliques.py", "test_terrain_tiles.py",
    "test_align_focal_drift.py", "test_autocontrol_orbit.py", "test_georef_synthetic.py", "test_pipeline.py",
    "test_calibrated_cameras.py", "test_rig_block.py", "test_panel_calibration.py", "test_autocontrol.py",
    "test_align_relaxed.py", "test_align_texture.py", "test_radiometry.py", "test_archive_scene.py",
)


def slowest_first(nodeid):
    """Sort key of a test: its file's place in SLOWEST_FIRST, the others after them."""
    name = nodeid.partition("::")[0].rsplit("/", 1)[-1]
    return SLOWEST_FIRST.index(name) if name in SLOWEST_FIRST else len(SLOWEST_FIRST)


def one_leg(nodeid):
    """True when the test of ``nodeid`` (``tests/test_x.py::test_y[param]`` or ``test_x.py::Class::test_y``) runs
    on the host leg only."""
    path, _, rest = nodeid.partition("::")
    key = path.rsplit("/", 1)[-1] + "::" + rest.split("[", 1)[0]
    return key in ONE_LEG or path.rsplit("/", 1)[-1] in ONE_LEG


# The edit-test loop (`make test-fast`, marker ``fast``): the tests every leg runs, less those marked slow and
# less these, each 6 s or more in the loop (measured 7 Dec: the loop took 7 min with them, two workers); they
# still run in `make test` and on every CI leg.
EDIT_LOOP_LEAVES_OUT = {
    "test_captures.py::test_qgis_process_runs_stackcaptures",  # 10 s
    "test_captures.py::test_the_stack_states_its_radiometry_and_corrects_the_vignetting",  # 8 s
    "test_dask.py::test_dask_products_are_identical_to_the_local_run",  # 21 s
    "test_dem_control.py::test_automatic_control_with_a_reference_dsm_alone_is_dem_control",  # 14 s
    "test_dem_control.py::test_processing_georeference_with_a_reference_dsm_alone",  # 8 s
    "test_dem_control.py::test_the_reference_dem_removes_the_tilt_and_offset_of_gps_heights",  # 7 s
    "test_dense.py::test_synthetic_dsm_accuracy",  # 12 s
    "test_epochs.py::test_orthophoto_of_the_second_epoch_on_the_earlier_dsm",  # 8 s
    "test_epochs.py::test_second_epoch_registered_on_the_earlier_block_with_no_gcp_and_no_prior",  # 8 s
    "test_masks.py::test_align_extracts_no_keypoints_under_the_masks",  # 6 s
    "test_masks.py::test_prepare_scanned_film_merges_polygons_with_the_scan_masks",  # 8 s
    "test_obliques.py::test_render_shows_sky_where_the_truth_says",  # 7 s
    "test_ortho.py::test_dsm_gaps_inside_the_data_are_filled_for_the_orthophoto",  # 11 s
    "test_ortho.py::test_mosaic_is_a_cog_with_alpha_in_the_workspace",  # 23 s
    "test_panel_calibration.py::test_a_normalised_stack_takes_the_light_of_its_panel",  # 8 s
    "test_panel_calibration.py::test_qgis_process_stacks_with_the_panel",  # 8 s
    "test_panel_calibration.py::test_the_stacked_photos_hold_reflectance_within_2_percent_of_the_truth",  # 13 s
    "test_pipeline_panel.py::test_a_bad_panel_is_refused_before_the_alignment_naming_it",  # 6 s
    "test_pipeline_panel.py::test_qgis_process_run_pipeline_refuses_a_bad_panel",  # 9 s
    "test_reliability_photos.py::test_changed_photo_is_refused_by_the_dsm_and_the_orthophoto",  # 8 s
    "test_scans.py::test_recovered_fiducials_within_half_a_pixel",  # 8 s
    "test_screening.py::test_qgis_process_names_each_skipped_file_once_and_adds_no_error_line",  # 7 s
    "test_seamlines.py::test_no_nodata_where_the_dsm_and_an_image_cover_the_cell",  # 16 s
    "test_seamlines.py::test_qgis_process_takes_the_edited_seamlines",  # 12 s
    "test_single_autocontrol.py::test_qgis_process_orthorectifies_with_automatic_control",  # 9 s
    "test_single_autocontrol.py::test_single_photo_is_oriented_and_orthorectified_by_automatic_control",  # 9 s
    "test_spectral_index.py::test_qgis_process_runs_spectralindex",  # 8 s
    "test_terrain.py::test_qgis_process_runs_the_terrain_algorithms",  # 17 s
    "test_ui_dock_layout.py::test_qgis_desktop_lang_de",  # 16 s
    "test_ui_dock_layout.py::test_qgis_desktop_with_the_toolbox_and_results_viewer",  # 15 s
    "test_ui_find_targets.py::test_one_key_confirms_or_rejects_each_found_observation",  # 6 s
}


def in_edit_loop(nodeid):
    """True when the test of ``nodeid`` runs in `make test-fast`: not one-leg, not left out above (slow tests are
    left out by the marker expression)."""
    path, _, rest = nodeid.partition("::")
    key = path.rsplit("/", 1)[-1] + "::" + rest.split("[", 1)[0]
    return not one_leg(nodeid) and key not in EDIT_LOOP_LEAVES_OUT
