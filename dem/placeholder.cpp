// The DEM core arrives with issue 3.
