"""Figures and report writing (the only library code that touches the file system besides the CLI)."""
