"""Independent references for the tests: closed forms and separate solves (scipy, MoorPy, MoorDyn) that share no
code with ropesim, so agreement with them means something."""
