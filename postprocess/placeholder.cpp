// Density fields arrive with issue 4.
