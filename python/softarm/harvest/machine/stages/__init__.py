"""The stages inside the harvesting states: the loop on the berry (placement, fine
positioning, the back-out) with its goal and end rules, the moves between (a plan
followed, a ramp, the way home), and the one send path they share."""
