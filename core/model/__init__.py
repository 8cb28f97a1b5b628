"""Textured 3-D models of the site (issue 50): a mesh from the DSM or the dense points, textured from the photos."""
