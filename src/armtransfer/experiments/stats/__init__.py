"""Statistics of trials: means and intervals, censored steps and survival, transfer metrics of
learning curves, and the benchmark's comparisons."""
