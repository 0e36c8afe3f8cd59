"""NumPy when it imports, else None: the one optional import of the package.

serve() works without NumPy, on nested lists; batched serving, encoded arrays and the geometry
helpers need it. Every module takes `np` from here, so that they all agree on whether NumPy is
there (a test blocks the import once and reloads the package to exercise the list path).
"""
try:
    import numpy as np
except ImportError:  # serve() still works, on nested lists
    np = None
