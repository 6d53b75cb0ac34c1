"""What a harvest leaves behind: the crash-safe log and its header, the report, the
recorded frames and their index, the rate, the plots and C1's picture of the bush."""
