"""The time-domain cross-check: a scene walked stage by stage through the force laws it declares, and
nothing else, with plots of each phase."""
