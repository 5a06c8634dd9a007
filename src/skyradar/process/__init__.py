"""Frame processing: range-Doppler, spur maps, detection, direction of arrival, ground filter."""
