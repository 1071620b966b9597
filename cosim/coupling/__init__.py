"""The only place the liquid and the robots meet: the co-simulation step loop, the pose/wrench exchange and the
measurements the pour controller reads from the liquid."""
