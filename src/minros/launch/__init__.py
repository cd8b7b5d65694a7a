"""roslaunch for minros: XML loader, substitution args, process monitor."""
