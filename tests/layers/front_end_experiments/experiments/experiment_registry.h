// The one experiments/ header a front end may include.
#pragma once
