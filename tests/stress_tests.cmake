# The stress test over extreme scenes (being written).
