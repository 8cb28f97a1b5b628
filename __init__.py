"""ArchaeoOrtho QGIS plugin entry point.  Nothing heavy is imported here."""


def classFactory(iface):  # noqa: N802 (QGIS API name)
    from .plugin import ArchaeoOrthoPlugin

    return ArchaeoOrthoPlugin(iface)
