"""The withheld-effect benchmark: runs generated with an effect the diagnosis does not know.

It checks :mod:`heavecomp.diagnosis` and sits beside it on the same layer; the diagnosis never
imports it.
"""
