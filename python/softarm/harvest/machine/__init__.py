"""The harvesting state machine (paper section III-D, fig. 4): its states and faults, the
per-berry workflow, the closed-loop stages inside the states and how a stage ends, and
the protocols of the devices it drives."""
