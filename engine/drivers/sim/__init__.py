"""The simulated vest: register-level models of the vest's chips behind real bus interfaces."""
