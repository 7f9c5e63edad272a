"""fe2003 (Rose & Ertl) preprocessing, GL-free: feature lines and planar subpatches, polygon
retriangulation, and the normal-map and wire-frame texture encodings."""
