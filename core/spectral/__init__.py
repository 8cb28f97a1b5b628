"""Spectral indices of any multi-band raster (issue 37 item 3: crop marks): NDVI, NDRE and a band expression,
computed block by block into a float32 Cloud-Optimized GeoTIFF.  A product on files, not a workspace stage:
``errors`` (SpectralError), ``options`` (IndexOptions), ``bands`` (which band is NIR, red, red edge ...),
``expression`` (the safe expression parser), ``index`` (the entry point ``spectral_index``)."""
