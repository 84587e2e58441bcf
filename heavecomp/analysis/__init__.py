"""Linear analysis of the CMC: operating point, linearisation (python-control),
frequency responses, describing functions and parameter sweeps.

Heavy imports (casadi, control) happen inside the sub-modules' functions.
"""
