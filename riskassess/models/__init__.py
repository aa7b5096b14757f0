"""Case -> model builders: typed case objects in, the physical packages' model inputs out."""
