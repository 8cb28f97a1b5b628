"""The QGIS floor under both faces: qgis.core helpers that the Processing algorithms and the dock both need.

- ``layers``: the styled result layers (DSM, orthomosaic, terrain, residuals, ...), loaded into a project in one
  order and named after their workspace;
- ``reference_layers``: a web, virtual or in-memory reference layer saved to a file for the automatic control.

Below ``processing_provider/`` and ``ui/`` (both may import it), above ``core/`` (it imports core, never a face);
no widgets here, so a headless ``qgis_process`` run pulls nothing from ``ui/``.
"""
